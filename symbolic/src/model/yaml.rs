//! YAML text → a located tree ([`YamlNode`]), using the saphyr event parser (YAML 1.2).
//!
//! serde-style deserialisation stops at the first error and forgets where values were; the
//! model pipeline needs every value's line and column and wants to report all problems of a
//! file at once, so it walks its own tree.

use saphyr_parser::{Event, Parser, ScalarStyle, Span};

use super::diagnostic::Diagnostic;
use super::located::{Located, Location};

/// A YAML value with the location of its first character.
#[derive(Debug, Clone, PartialEq)]
pub struct YamlNode {
    /// The value.
    pub kind: YamlKind,
    /// Where it starts (for a quoted scalar: its first content character).
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
        /// The text (unescaped).
        text: String,
        /// Whether it was quoted (then it is never null).
        quoted: bool,
    },
    /// `null`, `~` or an empty value.
    Null,
}

impl YamlKind {
    /// What the value is, for messages: `a map`, `a list`, `the scalar \`x\``, `nothing`.
    pub fn describe(&self) -> String {
        match self {
            YamlKind::Map(_) => "a map".to_string(),
            YamlKind::Seq(_) => "a list".to_string(),
            YamlKind::Scalar { text, .. } => format!("`{text}`"),
            YamlKind::Null => "nothing".to_string(),
        }
    }
}

fn location(span: &Span) -> Location {
    Location::from_zero_based(span.start.line().saturating_sub(1), span.start.col())
}

/// Parses `source` into its single document's tree.
///
/// # Errors
/// A diagnostic for a YAML syntax error (at the parser's marker), an anchor or alias, a
/// duplicate key, a non-scalar key, or a file with no document or more than one.
pub fn parse(source: &str) -> Result<YamlNode, Vec<Diagnostic>> {
    let mut events = Vec::new();
    for item in Parser::new_from_str(source) {
        match item {
            Ok(pair) => events.push(pair),
            Err(e) => {
                let m = e.marker();
                return Err(vec![Diagnostic::new(
                    Location::from_zero_based(m.line().saturating_sub(1), m.col()),
                    format!("YAML syntax error: {}", e.info()),
                ).with_help("model files are YAML maps of `key: value`; check the indentation, the colons, and that every `[` and `{` before this point is closed")]);
            }
        }
    }
    let mut builder = Builder {
        events,
        pos: 0,
        errors: Vec::new(),
    };
    let root = builder.document();
    if builder.errors.is_empty() {
        root.ok_or_else(|| {
            vec![
                Diagnostic::new(Location { line: 1, column: 1 }, "the model file is empty")
                    .with_help("start with `name: my_model` and `coordinates: [q]`"),
            ]
        })
    } else {
        Err(builder.errors)
    }
}

struct Builder<'a> {
    events: Vec<(Event<'a>, Span)>,
    pos: usize,
    errors: Vec<Diagnostic>,
}

impl<'a> Builder<'a> {
    fn next(&mut self) -> Option<(Event<'a>, Span)> {
        let e = self.events.get(self.pos).cloned();
        self.pos += 1;
        e
    }

    fn document(&mut self) -> Option<YamlNode> {
        let mut root = None;
        while let Some((event, span)) = self.next() {
            match event {
                Event::StreamStart | Event::DocumentEnd | Event::Nothing => {}
                Event::StreamEnd => break,
                Event::DocumentStart(_) => {
                    if root.is_some() {
                        self.errors.push(Diagnostic::new(
                            location(&span),
                            "a model file holds one YAML document, found a second",
                        ).with_help("remove the `---` separator and everything after it, or split the file"));
                        return root;
                    }
                    root = self.node();
                }
                _ => {
                    self.pos -= 1;
                    root = self.node();
                }
            }
        }
        root
    }

    fn anchor_check(&mut self, anchor: usize, span: &Span) {
        if anchor != 0 {
            self.errors.push(
                Diagnostic::new(location(span), "YAML anchors (`&name`) are not supported in model files")
                    .with_help("write the value out where it is used; expressions can refer to parameters instead"),
            );
        }
    }

    fn node(&mut self) -> Option<YamlNode> {
        let (event, span) = self.next()?;
        let loc = location(&span);
        Some(match event {
            Event::Scalar(text, style, anchor, _) => {
                self.anchor_check(anchor, &span);
                let quoted = matches!(style, ScalarStyle::SingleQuoted | ScalarStyle::DoubleQuoted);
                let is_null = !quoted
                    && matches!(style, ScalarStyle::Plain)
                    && matches!(text.as_ref(), "" | "~" | "null" | "Null" | "NULL");
                let location = if quoted { loc.offset(1) } else { loc };
                YamlNode {
                    kind: if is_null {
                        YamlKind::Null
                    } else {
                        YamlKind::Scalar {
                            text: text.into_owned(),
                            quoted,
                        }
                    },
                    location,
                }
            }
            Event::SequenceStart(anchor, _) => {
                self.anchor_check(anchor, &span);
                let mut items = Vec::new();
                loop {
                    match self.events.get(self.pos) {
                        Some((Event::SequenceEnd, _)) => {
                            self.pos += 1;
                            break;
                        }
                        None => break,
                        _ => match self.node() {
                            Some(n) => items.push(n),
                            None => break,
                        },
                    }
                }
                YamlNode {
                    kind: YamlKind::Seq(items),
                    location: loc,
                }
            }
            Event::MappingStart(anchor, _) => {
                self.anchor_check(anchor, &span);
                let mut entries: Vec<(Located<String>, YamlNode)> = Vec::new();
                loop {
                    match self.events.get(self.pos) {
                        Some((Event::MappingEnd, _)) => {
                            self.pos += 1;
                            break;
                        }
                        None => break,
                        _ => {}
                    }
                    let Some(key) = self.node() else { break };
                    let Some(value) = self.node() else { break };
                    let key_text = match key.kind {
                        YamlKind::Scalar { text, .. } => text,
                        YamlKind::Null => String::new(),
                        other => {
                            self.errors.push(Diagnostic::new(
                                key.location,
                                format!("a key must be a name, found {}", other.describe()),
                            ));
                            continue;
                        }
                    };
                    if let Some((first, _)) = entries.iter().find(|(k, _)| k.value == key_text) {
                        self.errors.push(
                            Diagnostic::new(key.location, format!("duplicate key `{key_text}`"))
                                .with_help(format!(
                                    "`{key_text}` is already given at line {}; keep one",
                                    first.location.line
                                )),
                        );
                        continue;
                    }
                    entries.push((Located::new(key_text, key.location), value));
                }
                YamlNode {
                    kind: YamlKind::Map(entries),
                    location: loc,
                }
            }
            Event::Alias(_) => {
                self.errors.push(
                    Diagnostic::new(
                        loc,
                        "YAML aliases (`*name`) are not supported in model files",
                    )
                    .with_help("write the value out where it is used"),
                );
                YamlNode {
                    kind: YamlKind::Null,
                    location: loc,
                }
            }
            _ => YamlNode {
                kind: YamlKind::Null,
                location: loc,
            },
        })
    }
}

/// The text of the trailing `# comment` on line `line` (1-based) of `source`, trimmed, if
/// any. A `#` inside quotes, or not preceded by a space, does not start a comment.
pub fn trailing_comment(source: &str, line: u32) -> Option<String> {
    let text = source.lines().nth(line.checked_sub(1)? as usize)?;
    let mut quote: Option<char> = None;
    let mut previous = ' ';
    for (i, c) in text.char_indices() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if c == '\'' || c == '"' => quote = Some(c),
            None if c == '#' && previous.is_whitespace() => {
                let comment = text[i + 1..].trim();
                return (!comment.is_empty()).then(|| comment.to_string());
            }
            None => {}
        }
        previous = c;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locations_are_one_based() {
        let src = "name: x\nparameters:\n  m: 1.0  # kg\n  s: 'a # b'\n";
        let root = parse(src).unwrap();
        let YamlKind::Map(entries) = &root.kind else {
            panic!()
        };
        assert_eq!(entries[0].0.location, Location { line: 1, column: 1 });
        assert_eq!(entries[0].1.location, Location { line: 1, column: 7 });
        let YamlKind::Map(params) = &entries[1].1.kind else {
            panic!()
        };
        assert_eq!(params[0].1.location, Location { line: 3, column: 6 });
        assert_eq!(params[1].1.location, Location { line: 4, column: 7 });
        assert_eq!(trailing_comment(src, 3).as_deref(), Some("kg"));
        assert_eq!(trailing_comment(src, 4), None);
    }

    #[test]
    fn duplicate_keys_and_syntax_errors() {
        let e = parse("a: 1\na: 2\n").unwrap_err();
        assert_eq!(e[0].location, Location { line: 2, column: 1 });
        assert!(e[0].message.contains("duplicate key `a`"));
        let e = parse("a: [1, 2\n").unwrap_err();
        assert!(e[0].message.starts_with("YAML syntax error"));
    }
}
