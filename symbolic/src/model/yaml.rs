//! YAML text → a located tree ([`YamlNode`]), using the saphyr event parser (YAML 1.2).
//!
//! serde-style deserialisation stops at the first error and forgets where values were; the
//! model pipeline needs every value's line and column and wants to report all problems of a
//! file at once, so it walks its own tree.
//!
//! Model files use plain YAML: maps, lists and scalars. Anchors (`&a`), aliases (`*a`) and
//! tags (`!!str`) are reported as errors (an alias is still resolved, so that the rest of the
//! file is checked as if it had been written out). Duplicate keys are errors; the first one
//! is kept.
//!
//! Locations: saphyr's markers have 1-based lines and 0-based columns counted in characters.
//! They become [`Location`]s only through [`Location::from_zero_based`], in `location`. A
//! node's location is its first character; for a quoted scalar, the first character *inside*
//! the quotes, so that offsets into the scalar's text are columns in the file.

use saphyr_parser::{Event, Marker, Parser, ScalarStyle, Span, Tag};

use super::diagnostic::Diagnostic;
use super::located::{Located, Location};

/// A YAML value with the location of its first character.
#[derive(Debug, Clone, PartialEq)]
pub struct YamlNode {
    /// The value.
    pub kind: YamlKind,
    /// Where it starts (for a quoted scalar: its first content character; for a block
    /// scalar `|`/`>`: the first character of its content line).
    pub location: Location,
}

/// The forms of a YAML value.
#[derive(Debug, Clone, PartialEq)]
pub enum YamlKind {
    /// A mapping, in file order.
    Map(Vec<(Located<String>, YamlNode)>),
    /// A sequence.
    Seq(Vec<YamlNode>),
    /// A scalar's text; `quoted` for `'…'` and `"…"`.
    Scalar {
        /// The text (unescaped; a multi-line plain scalar is folded into one line).
        text: String,
        /// Whether it was quoted (then it is never null).
        quoted: bool,
    },
    /// `null`, `~` or an empty value.
    Null,
}

impl YamlKind {
    /// What the value is, for messages: `a map`, `a list`, `` `x` ``, `nothing`.
    pub fn describe(&self) -> String {
        match self {
            YamlKind::Map(_) => "a map".to_string(),
            YamlKind::Seq(_) => "a list".to_string(),
            YamlKind::Scalar { text, .. } => {
                let one_line = text.trim().replace('\n', " ");
                if one_line.chars().count() > 40 {
                    let short: String = one_line.chars().take(37).collect();
                    format!("`{short}...`")
                } else {
                    format!("`{one_line}`")
                }
            }
            YamlKind::Null => "nothing".to_string(),
        }
    }
}

/// The location of a saphyr marker (1-based line, 0-based column in characters).
fn location(marker: &Marker) -> Location {
    Location::from_zero_based(marker.line().saturating_sub(1), marker.col())
}

/// Parses `source` into its single document's tree.
///
/// # Errors
/// A diagnostic for a YAML syntax error (at the parser's marker), an anchor, alias or tag,
/// a duplicate key, a key that is not a scalar, or a file with no document or more than one.
pub fn parse(source: &str) -> Result<YamlNode, Vec<Diagnostic>> {
    match parse_partial(source) {
        (Some(root), errors) if errors.is_empty() => Ok(root),
        (_, errors) if errors.is_empty() => Err(vec![empty_file()]),
        (_, errors) => Err(errors),
    }
}

/// Parses `source` as far as possible: the tree, if the file is well-formed YAML, together
/// with every diagnostic (see [`parse`]).
///
/// After a syntax error there is no tree. After the other errors there is: a duplicate key
/// keeps its first value, an alias is resolved, anchors and tags are ignored. This lets
/// [`super::load`] report the file's other problems in the same run.
pub fn parse_partial(source: &str) -> (Option<YamlNode>, Vec<Diagnostic>) {
    let mut events = Vec::new();
    for item in Parser::new_from_str(source) {
        match item {
            Ok(pair) => events.push(pair),
            Err(e) => {
                let at = location(e.marker());
                let d = match unclosed_flow(source, at) {
                    Some((open, opened_at)) => {
                        let close = if open == '[' { ']' } else { '}' };
                        Diagnostic::new(
                            at,
                            format!(
                                "YAML syntax error: the `{open}` opened at {opened_at} is not closed ({})",
                                e.info()
                            ),
                        )
                        .with_help(format!(
                            "close it with `{close}` before this point; inside `{open}…{close}`, items are separated by `,`"
                        ))
                    }
                    None => character_error(source, at, e.info())
                        .unwrap_or_else(|| syntax_error(at, e.info())),
                };
                return (None, vec![d]);
            }
        }
    }
    let mut builder = Builder {
        events: events.into_iter(),
        peeked: None,
        anchors: Vec::new(),
        alias_budget: ALIAS_BUDGET,
        errors: Vec::new(),
    };
    let root = builder.document();
    if root.is_none() && builder.errors.is_empty() {
        builder.errors.push(empty_file());
    }
    (root, builder.errors)
}

fn empty_file() -> Diagnostic {
    Diagnostic::new(Location { line: 1, column: 1 }, "the model file is empty")
        .with_help("start with `name: my_model` and `coordinates: [q]`")
}

/// A syntax error about one character, located at that character: a control character
/// (such as NUL), which the parser calls "unprintable" at the end of the value it was
/// scanning, and a tab, which it may report at the end of the line before the one that
/// starts with it. `None` for other errors.
fn character_error(source: &str, at: Location, info: &str) -> Option<Diagnostic> {
    let (what, help, found): (String, &str, fn(char) -> bool) = if info.contains("unprintable") {
        (
            "a control character is not allowed in a model file".to_string(),
            "model files are plain text: remove it (it may come from a copy and paste or a binary file)",
            |c| c.is_control() && !matches!(c, '\t' | '\n' | '\r'),
        )
    } else if info.contains("tab") {
        (
            "a tab is used for indentation".to_string(),
            "indent with spaces",
            |c| c == '\t',
        )
    } else {
        return None;
    };
    // The first such character at or after the reported position.
    let (line, column) = source
        .lines()
        .enumerate()
        .skip(at.line.saturating_sub(1) as usize)
        .find_map(|(i, text)| {
            let from = if i + 1 == at.line as usize {
                at.column.saturating_sub(1) as usize
            } else {
                0
            };
            text.chars()
                .enumerate()
                .skip(from)
                .find(|(_, c)| found(*c))
                .map(|(j, _)| (i as u32 + 1, j as u32 + 1))
        })?;
    let c = source
        .lines()
        .nth(line as usize - 1)?
        .chars()
        .nth(column as usize - 1)?;
    let what = if c == '\t' {
        what
    } else {
        format!("{what} (U+{:04X})", c as u32)
    };
    Some(
        Diagnostic::new(
            Location { line, column },
            format!("YAML syntax error: {what}"),
        )
        .with_help(help),
    )
}

/// The text of a model file from its bytes, or a located error at the first byte that is not
/// UTF-8 (with the line and column of the text before it).
///
/// # Errors
/// The diagnostic at the first invalid byte.
pub fn decode(bytes: &[u8]) -> Result<&str, Diagnostic> {
    std::str::from_utf8(bytes).map_err(|e| {
        let valid = &bytes[..e.valid_up_to()];
        // Valid UTF-8 up to here, so this cannot fail.
        let before = std::str::from_utf8(valid).unwrap_or_default();
        let line = before.matches('\n').count() as u32 + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) as u32 + 1;
        Diagnostic::new(
            Location { line, column },
            format!(
                "the file is not UTF-8 text: byte 0x{:02X} (byte {} of the file) starts no character",
                bytes[e.valid_up_to()],
                e.valid_up_to() + 1
            ),
        )
        .with_help("save the file as UTF-8 (model files are plain text)")
    })
}

/// A syntax error in the words of a model-file author, keeping the parser's own words at the
/// end (they name the exact token).
fn syntax_error(at: Location, info: &str) -> Diagnostic {
    let (what, help) = if info.contains("did not find expected ',' or ']'") {
        (
            "a `[` list is not closed",
            "close the list with `]`, and separate its items with `,`",
        )
    } else if info.contains("did not find expected ',' or '}'") {
        (
            "a `{` map is not closed",
            "close the map with `}`, and separate its entries with `,`",
        )
    } else if info.contains("illegal placement of ':' indicator") {
        (
            "unexpected `:`",
            "a `[` or `{` on an earlier line may not be closed; a value containing `: ` must be quoted",
        )
    } else if info.contains("mapping values are not allowed") {
        (
            "unexpected `key: value` here",
            "check the indentation (keys of one map start in the same column); a value containing `: ` must be quoted",
        )
    } else if info.contains("simple key expect ':'") || info.contains("could not find expected ':'")
    {
        (
            "expected `:` after a key",
            "every line of a map is `key: value`; a list item starts with `- `",
        )
    } else if info.contains("did not find expected '-' indicator")
        || info.contains("did not find expected key")
    {
        (
            "the indentation does not match",
            "items of one list (`- …`) or one map (`key: …`) start in the same column",
        )
    } else if info.contains("tabs disallowed") || info.contains("tab") {
        ("a tab is used for indentation", "indent with spaces")
    } else if info.contains("quoted scalar") && info.contains("end of stream") {
        (
            "a quoted value is not closed",
            "close the quote with the same character that opened it",
        )
    } else if info.contains("recursion limit") {
        (
            "the file is nested too deeply",
            "model files need only a few levels of maps and lists",
        )
    } else if info.contains("misplaced bracket") {
        (
            "a `]` or `}` closes nothing",
            "remove it, or open the list or map it should close",
        )
    } else if info.contains("unexpected character") {
        (
            "this character cannot start a value",
            "quote the value (`'…'`) if it starts with `@`, `` ` `` or another special character",
        )
    } else {
        (
            "the file is not valid YAML",
            "model files are YAML maps of `key: value`; check the indentation, the colons, and that every `[` and `{` is closed",
        )
    };
    Diagnostic::new(at, format!("YAML syntax error: {what} ({info})")).with_help(help)
}

/// The innermost flow collection (`[` or `{`) opened before `upto` and not closed, with where
/// it was opened: the usual cause of a syntax error reported at a later `:`.
///
/// A bracket opens a collection only where a value can start (after `: `, `- `, `[`, `{`,
/// `,`, or at the start of a line), not inside a plain value (`see [1]`), a quoted value or
/// a comment.
fn unclosed_flow(source: &str, upto: Location) -> Option<(char, Location)> {
    let mut stack: Vec<(char, Location)> = Vec::new();
    for (line_index, line) in source.lines().enumerate() {
        let line_no = line_index as u32 + 1;
        if line_no > upto.line {
            break;
        }
        let chars: Vec<char> = line.chars().collect();
        let mut previous: Option<char> = None; // last non-space character on the line
        let mut k = 0;
        while k < chars.len() {
            let here = Location {
                line: line_no,
                column: k as u32 + 1,
            };
            if here >= upto {
                break;
            }
            let c = chars[k];
            let spaced = k == 0 || chars[k - 1].is_whitespace();
            let value_start = match previous {
                None => true,
                Some('[' | '{' | ',') => true,
                Some(':' | '-') => spaced,
                Some(_) => false,
            };
            match c {
                '#' if spaced => break,
                '[' | '{' if value_start || !stack.is_empty() => stack.push((c, here)),
                ']' | '}' if !stack.is_empty() => {
                    stack.pop();
                }
                '\'' | '"' if value_start => {
                    k += 1;
                    while k < chars.len() && chars[k] != c {
                        k += if c == '"' && chars[k] == '\\' { 2 } else { 1 };
                    }
                }
                _ => {}
            }
            if !c.is_whitespace() {
                previous = Some(c);
            }
            k += 1;
        }
    }
    stack.pop()
}

/// How a tag is written in the file (`!!str`, `!local`).
fn tag_text(tag: &Tag) -> String {
    if tag.handle == "tag:yaml.org,2002:" || tag.handle == "!!" {
        format!("!!{}", tag.suffix)
    } else if tag.handle == "!" {
        format!("!{}", tag.suffix)
    } else {
        format!("{}{}", tag.handle, tag.suffix)
    }
}

/// How many nodes aliases may copy in one file, in all.
const ALIAS_BUDGET: usize = 10_000;

/// The number of nodes in a tree.
fn size(node: &YamlNode) -> usize {
    1 + match &node.kind {
        YamlKind::Map(entries) => entries.iter().map(|(_, v)| size(v)).sum(),
        YamlKind::Seq(items) => items.iter().map(size).sum(),
        YamlKind::Scalar { .. } | YamlKind::Null => 0,
    }
}

struct Builder<'a> {
    events: std::vec::IntoIter<(Event<'a>, Span)>,
    peeked: Option<(Event<'a>, Span)>,
    /// Anchored nodes by anchor id, to resolve aliases.
    anchors: Vec<(usize, YamlNode)>,
    /// Nodes still allowed to be copied by aliases (nested aliases grow exponentially).
    alias_budget: usize,
    errors: Vec<Diagnostic>,
}

impl<'a> Builder<'a> {
    fn next(&mut self) -> Option<(Event<'a>, Span)> {
        self.peeked.take().or_else(|| self.events.next())
    }

    fn peek(&mut self) -> Option<&Event<'a>> {
        if self.peeked.is_none() {
            self.peeked = self.events.next();
        }
        self.peeked.as_ref().map(|(e, _)| e)
    }

    fn document(&mut self) -> Option<YamlNode> {
        let mut root = None;
        while let Some((event, span)) = self.next() {
            match event {
                Event::StreamStart | Event::DocumentEnd | Event::Nothing => {}
                Event::StreamEnd => break,
                Event::DocumentStart(_) => {
                    if root.is_some() {
                        self.errors.push(
                            Diagnostic::new(
                                location(&span.start),
                                "a model file holds one YAML document, found a second",
                            )
                            .with_help(
                                "remove the `---` separator and everything after it, or split the file",
                            ),
                        );
                        return root;
                    }
                }
                other => {
                    if root.is_some() {
                        // Cannot happen with a well-formed event stream; ignore it.
                        continue;
                    }
                    root = Some(self.node(other, span));
                }
            }
        }
        root
    }

    fn properties(&mut self, anchor: usize, tag: Option<&Tag>, span: &Span) {
        if anchor != 0 {
            self.errors.push(
                Diagnostic::new(
                    location(&span.start),
                    "YAML anchors (`&name`) are not supported in model files",
                )
                .with_help(
                    "write the value out where it is used; to share a number, make it a parameter",
                ),
            );
        }
        if let Some(tag) = tag {
            self.errors.push(
                Diagnostic::new(
                    location(&span.start),
                    format!(
                        "YAML tags such as `{}` are not supported in model files",
                        tag_text(tag)
                    ),
                )
                .with_help("remove the tag; values are read as expressions or names"),
            );
        }
    }

    fn remember(&mut self, anchor: usize, node: &YamlNode) {
        if anchor != 0 {
            self.anchors.push((anchor, node.clone()));
        }
    }

    /// The node that starts with `event`, consuming its children.
    // Long: one arm per YAML event (scalar, sequence, map, alias), each building its located node;
    // the match is the event set.
    fn node(&mut self, event: Event<'a>, span: Span) -> YamlNode {
        let loc = location(&span.start);
        match event {
            Event::Scalar(text, style, anchor, tag) => {
                self.properties(anchor, tag.as_deref(), &span);
                let quoted = matches!(style, ScalarStyle::SingleQuoted | ScalarStyle::DoubleQuoted);
                let is_null = matches!(style, ScalarStyle::Plain)
                    && matches!(text.as_ref(), "" | "~" | "null" | "Null" | "NULL");
                // The span of a quoted scalar starts at the quote; its text one further.
                let location = if quoted && anchor == 0 && tag.is_none() {
                    loc.offset(1)
                } else {
                    loc
                };
                let node = YamlNode {
                    kind: if is_null {
                        YamlKind::Null
                    } else {
                        YamlKind::Scalar {
                            text: text.into_owned(),
                            quoted,
                        }
                    },
                    location,
                };
                self.remember(anchor, &node);
                node
            }
            Event::SequenceStart(anchor, tag) => {
                self.properties(anchor, tag.as_deref(), &span);
                let mut items = Vec::new();
                loop {
                    match self.next() {
                        None | Some((Event::SequenceEnd, _)) => break,
                        Some((event, span)) => {
                            let item = self.node(event, span);
                            items.push(item);
                        }
                    }
                }
                let node = YamlNode {
                    kind: YamlKind::Seq(items),
                    location: loc,
                };
                self.remember(anchor, &node);
                node
            }
            Event::MappingStart(anchor, tag) => {
                self.properties(anchor, tag.as_deref(), &span);
                let mut entries: Vec<(Located<String>, YamlNode)> = Vec::new();
                // The index of each key in `entries`, so that finding a duplicate is not a
                // scan (a map of many keys would be quadratic).
                let mut keys: std::collections::HashMap<String, usize> =
                    std::collections::HashMap::new();
                loop {
                    let (key_event, key_span) = match self.next() {
                        None | Some((Event::MappingEnd, _)) => break,
                        Some(pair) => pair,
                    };
                    let key = self.node(key_event, key_span);
                    if matches!(self.peek(), None | Some(Event::MappingEnd)) {
                        // Cannot happen with a well-formed event stream: a key without value.
                        break;
                    }
                    let Some((value_event, value_span)) = self.next() else {
                        break;
                    };
                    let value = self.node(value_event, value_span);
                    let key_text = match key.kind {
                        YamlKind::Scalar { text, .. } => text,
                        other => {
                            self.errors.push(
                                Diagnostic::new(
                                    key.location,
                                    format!("a key must be a name, found {}", other.describe()),
                                )
                                .with_help("write `name: value`"),
                            );
                            continue;
                        }
                    };
                    if let Some(&index) = keys.get(key_text.as_str()) {
                        let first: &Located<String> = &entries[index].0;
                        self.errors.push(
                            Diagnostic::new(key.location, format!("duplicate key `{key_text}`"))
                                .with_help(format!(
                                    "`{key_text}` is already given at {}; keep one",
                                    first.location
                                )),
                        );
                        continue;
                    }
                    keys.insert(key_text.clone(), entries.len());
                    entries.push((Located::new(key_text, key.location), value));
                }
                let node = YamlNode {
                    kind: YamlKind::Map(entries),
                    location: loc,
                };
                self.remember(anchor, &node);
                node
            }
            Event::Alias(id) => {
                self.errors.push(
                    Diagnostic::new(
                        loc,
                        "YAML aliases (`*name`) are not supported in model files",
                    )
                    .with_help("write the value out where it is used"),
                );
                let anchored = self.anchors.iter().rev().find(|(a, _)| *a == id);
                match anchored.map(|(_, node)| (size(node), node)) {
                    Some((n, node)) if n <= self.alias_budget => {
                        self.alias_budget -= n;
                        node.clone()
                    }
                    _ => YamlNode {
                        kind: YamlKind::Null,
                        location: loc,
                    },
                }
            }
            // Stream and document events do not occur inside a document.
            _ => YamlNode {
                kind: YamlKind::Null,
                location: loc,
            },
        }
    }
}

/// The text of the trailing `# comment` on line `line` (1-based) of `source`, trimmed, if
/// any.
///
/// As in YAML, a `#` starts a comment only at the start of the line or after whitespace, and
/// not inside a quoted value (`'a # b'`, `"a # b"`, with `''` and `\"` escapes). A quote
/// opens a quoted value only where a value can start (after whitespace, `[`, `{`, `,`, `:`
/// or `-`), so the apostrophe of `it's` does not. A line that ends inside an open quote has
/// no comment.
pub fn trailing_comment(source: &str, line: u32) -> Option<String> {
    trailing_comment_of_line(source.lines().nth(line.checked_sub(1)? as usize)?)
}

/// The text of the trailing `# comment` of the line `text`, trimmed, if any (the rules of
/// [`trailing_comment`], for a caller that has the file's lines at hand: looking a line up
/// by number is linear in the file, and a file of many parameters asks once per parameter).
pub fn trailing_comment_of_line(text: &str) -> Option<String> {
    let chars: Vec<(usize, char)> = text.char_indices().collect();
    let mut previous: Option<char> = None;
    let mut k = 0;
    while k < chars.len() {
        let (i, c) = chars[k];
        let value_may_start =
            previous.is_none_or(|p| p.is_whitespace() || matches!(p, '[' | '{' | ',' | ':' | '-'));
        match c {
            '#' if previous.is_none_or(char::is_whitespace) => {
                let comment = text[i + 1..].trim();
                return (!comment.is_empty()).then(|| comment.to_string());
            }
            '\'' | '"' if value_may_start => {
                k += 1;
                loop {
                    let &(_, d) = chars.get(k)?;
                    let escaped = (c == '"' && d == '\\')
                        || (d == c && c == '\'' && chars.get(k + 1).map(|x| x.1) == Some('\''));
                    if escaped {
                        k += 2;
                    } else if d == c {
                        break;
                    } else {
                        k += 1;
                    }
                }
            }
            _ => {}
        }
        previous = chars.get(k).map(|x| x.1);
        k += 1;
    }
    None
}

/// Where each character of a scalar's `text` is in `source`, given the location of its first
/// character; one more entry gives the location just after the last character.
///
/// A plain or quoted scalar that spans several lines is folded by YAML (a line break and the
/// indentation become one space), and a block scalar (`|`, `>`) starts on the line after its
/// indicator. This follows the text through the source, character by character, skipping
/// the line breaks, indentation, quotes and escape characters that the folding removed. It
/// returns `None` when the text cannot be followed (escapes such as `\t`); the caller then
/// counts columns from the first character.
pub fn char_locations(source: &str, start: Location, text: &str) -> Option<Vec<Location>> {
    char_locations_in_lines(&source.lines().collect::<Vec<_>>(), start, text)
}

/// [`char_locations`] over the source's `lines` (collected once by a caller that locates
/// many scalars: skipping to a line of the source text is linear in the file, which made a
/// file of many expressions quadratic).
pub fn char_locations_in_lines(
    lines: &[&str],
    start: Location,
    text: &str,
) -> Option<Vec<Location>> {
    let mut lines = lines
        .iter()
        .copied()
        .skip(start.line.checked_sub(1)? as usize);
    let mut line_no = start.line;
    let first: Vec<char> = lines.next()?.chars().collect();
    let mut col = start.column.checked_sub(1)? as usize;
    if col > first.len() {
        return None;
    }
    let mut current = first;
    let mut out = Vec::with_capacity(text.chars().count() + 1);
    let here = |line_no: u32, col: usize| Location {
        line: line_no,
        column: col as u32 + 1,
    };
    for c in text.chars() {
        loop {
            match current.get(col) {
                Some(&s) if s == c => {
                    out.push(here(line_no, col));
                    col += 1;
                    break;
                }
                // Folding turned a line break (and indentation) into this whitespace.
                None if c.is_whitespace() => {
                    out.push(here(line_no, col));
                    current = lines
                        .next()
                        .map(|l| l.chars().collect())
                        .unwrap_or_default();
                    line_no += 1;
                    col = 0;
                    while current.get(col).is_some_and(|s| s.is_whitespace()) {
                        col += 1;
                    }
                    break;
                }
                Some(&s) if c.is_whitespace() && !s.is_whitespace() => {
                    // Whitespace in the text that is not in the source (an escape).
                    out.push(here(line_no, col));
                    break;
                }
                Some(&s) if s.is_whitespace() || matches!(s, '\\' | '\'' | '"') => col += 1,
                None => {
                    // The text continues on the next line (block scalars, folded lines).
                    current = lines.next()?.chars().collect();
                    line_no += 1;
                    col = 0;
                }
                Some(_) => return None,
            }
        }
    }
    out.push(here(line_no, col));
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(line: u32, column: u32) -> Location {
        Location { line, column }
    }

    fn entries(node: &YamlNode) -> &[(Located<String>, YamlNode)] {
        match &node.kind {
            YamlKind::Map(e) => e,
            other => panic!("expected a map, found {other:?}"),
        }
    }

    #[test]
    fn locations_are_one_based_and_in_characters() {
        let src = "name: x\nparameters:\n  m: 1.0  # kg\n  s: 'a # b'\n  θ: \"é\" # c\n";
        let root = parse(src).unwrap();
        let top = entries(&root);
        assert_eq!(top[0].0.location, at(1, 1));
        assert_eq!(top[0].1.location, at(1, 7));
        let params = entries(&top[1].1);
        assert_eq!(params[0].1.location, at(3, 6));
        // Quoted: the first character inside the quotes.
        assert_eq!(params[1].1.location, at(4, 7));
        assert_eq!(params[2].0.location, at(5, 3));
        assert_eq!(params[2].1.location, at(5, 7));
        assert_eq!(trailing_comment(src, 3).as_deref(), Some("kg"));
        assert_eq!(trailing_comment(src, 4), None);
        assert_eq!(trailing_comment(src, 5).as_deref(), Some("c"));
    }

    #[test]
    fn trailing_comments_respect_quotes() {
        let c = |s: &str| trailing_comment(s, 1);
        assert_eq!(c("a: 1 # kg").as_deref(), Some("kg"));
        assert_eq!(c("a: 1#x"), None);
        assert_eq!(c("a: 'x # y'"), None);
        assert_eq!(c("a: 'it''s # no' # yes").as_deref(), Some("yes"));
        assert_eq!(c(r#"a: "q\" # no" # yes"#).as_deref(), Some("yes"));
        assert_eq!(c("d: it's a pendulum # note").as_deref(), Some("note"));
        assert_eq!(c("a: 'open # no"), None);
        assert_eq!(c("a: 1 #"), None);
        assert_eq!(trailing_comment("a: 1", 0), None);
        assert_eq!(trailing_comment("a: 1", 7), None);
    }

    #[test]
    fn duplicate_keys_and_syntax_errors() {
        let e = parse("a: 1\na: 2\n").unwrap_err();
        assert_eq!(e[0].location, at(2, 1));
        assert!(e[0].message.contains("duplicate key `a`"));
        assert!(e[0].help.as_deref().unwrap().contains("1:1"));
        let e = parse("a: [1, 2\n").unwrap_err();
        assert!(e[0].message.starts_with("YAML syntax error"));
        let e = parse("a: b: c\n").unwrap_err();
        assert_eq!(e[0].location, at(1, 5));
        assert!(e[0].message.contains("unexpected `key: value`"));
        let e = parse("a:\n\t- x\n").unwrap_err();
        assert!(e[0].message.contains("tab"));
        let e = parse("").unwrap_err();
        assert!(e[0].message.contains("empty"));
        let e = parse("a: 1\n---\nb: 2\n").unwrap_err();
        assert_eq!(e[0].location, at(2, 1));
    }

    #[test]
    fn an_unclosed_flow_collection_is_named() {
        let e = parse("name: x\ncoordinates: [x\nkinetic: x_dot^2\n").unwrap_err();
        assert!(
            e[0].message
                .contains("the `[` opened at 2:14 is not closed"),
            "{e:?}"
        );
        let e = parse("a: { b: [1, 2], c: 3\nd: 4\n").unwrap_err();
        assert!(
            e[0].message.contains("the `{` opened at 1:4 is not closed"),
            "{e:?}"
        );
        // Brackets inside plain values, quotes and comments do not count.
        assert_eq!(unclosed_flow("a: see [1\nb: 'x[' # [\n", at(3, 1)), None);
    }

    #[test]
    fn anchors_aliases_and_tags_are_reported_but_resolved() {
        let (root, errors) = parse_partial("a: &x [1, 2]\nb: *x\nc: !!str 3\n");
        let messages: Vec<&str> = errors.iter().map(|d| d.message.as_str()).collect();
        assert_eq!(errors.len(), 3, "{messages:?}");
        assert!(messages[0].contains("anchors"));
        assert!(messages[1].contains("aliases"));
        assert!(messages[2].contains("`!!str`"));
        let root = root.unwrap();
        let top = entries(&root);
        assert!(matches!(&top[1].1.kind, YamlKind::Seq(items) if items.len() == 2));
    }

    #[test]
    fn nested_aliases_do_not_blow_up() {
        let mut src = String::from("a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n");
        for i in 1..30 {
            let refs = vec![format!("*a{}", i - 1); 10].join(", ");
            src.push_str(&format!("a{i}: &a{i} [{refs}]\n"));
        }
        let (root, errors) = parse_partial(&src);
        assert!(root.is_some());
        assert!(errors.iter().all(|d| d.message.contains("not supported")));
        assert!(size(&root.unwrap()) < 100 * ALIAS_BUDGET);
    }

    #[test]
    fn null_and_quoted_scalars() {
        let root = parse("a:\nb: ~\nc: 'null'\nd: null\n").unwrap();
        let top = entries(&root);
        assert_eq!(top[0].1.kind, YamlKind::Null);
        assert_eq!(top[1].1.kind, YamlKind::Null);
        assert!(matches!(
            &top[2].1.kind,
            YamlKind::Scalar { quoted: true, .. }
        ));
        assert_eq!(top[3].1.kind, YamlKind::Null);
    }

    #[test]
    fn char_locations_follow_folded_and_block_scalars() {
        let src = "k: m*x\n  + y\np: >\n  a +\n  b\nq: \"u\n   v\"\n";
        let root = parse(src).unwrap();
        let top = entries(&root);
        let text = |n: &YamlNode| match &n.kind {
            YamlKind::Scalar { text, .. } => text.clone(),
            _ => panic!(),
        };
        let k = &top[0].1;
        assert_eq!(text(k), "m*x + y");
        let locs = char_locations(src, k.location, &text(k)).unwrap();
        assert_eq!(locs[0], at(1, 4));
        assert_eq!(locs[4], at(2, 3)); // `+`
        assert_eq!(locs[6], at(2, 5)); // `y`
        let p = &top[1].1;
        assert_eq!(p.location, at(4, 3));
        let locs = char_locations(src, p.location, &text(p)).unwrap();
        assert_eq!(locs[4], at(5, 3)); // `b`
        let q = &top[2].1;
        let locs = char_locations(src, q.location, &text(q)).unwrap();
        assert_eq!(locs[0], at(6, 5));
        assert_eq!(locs[2], at(7, 4));
        // Single line: plain offsets.
        let locs = char_locations("a: θ+1", at(1, 4), "θ+1").unwrap();
        assert_eq!(locs, vec![at(1, 4), at(1, 5), at(1, 6), at(1, 7)]);
        // Escapes that cannot be followed.
        assert_eq!(char_locations("a: \"x\\ty\"", at(1, 5), "x\ty"), None);
    }
}
