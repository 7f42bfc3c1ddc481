//! Located YAML tree → typed [`ModelFile`], reporting every unknown key, wrong type and
//! malformed expression at once.
//!
//! The pass never stops at the first problem: an entry that cannot be built is reported and
//! left out, and what was left out is recorded in [`Incomplete`] so that the cross-object
//! checks ([`super::check`]) do not report its consequences a second time.

use std::collections::HashMap;

use super::ast::{BinOp, Expr, ExprKind};
use super::diagnostic::{Diagnostic, Diagnostics};
use super::file::*;
use super::located::{Located, Location};
use super::parser::{closest, eval_expr, identifiers, parse_expr_mapped};
use super::yaml::{YamlKind, YamlNode, char_locations_in_lines, trailing_comment_of_line};

type Entries = [(Located<String>, YamlNode)];

/// Expressions by name, in file order.
type KeyedExprs = Vec<(Located<String>, Expr)>;

/// The most generalized coordinates a model may have (a located error at the `coordinates`
/// list beyond it). The mass matrix is derived, simplified and evaluated as a dense `n × n`
/// matrix, so that memory and time grow as `n²` and faster: measured in a release build, a
/// chain of N masses (`eomgen new n-mass-chain`, written by a script beyond 1000) took, in
/// CPU time and peak memory, for `eomgen check` 4.4 s and 97 MiB at N = 1000, 22 s and
/// 345 MiB at 2000; for `simulate --t-end 0.01` 1.9 s and 122 MiB at 1000, 8.2 s and
/// 423 MiB at 2000 (docs/performance.md has the rest). The limit is the largest of these
/// sizes that loads, checks and takes a first step within about 10 s and 2 GB, and the
/// template's largest; a 10,000-mass chain (1.4 MB, within
/// [`MAX_FILE_BYTES`](super::MAX_FILE_BYTES)) needed 5.8 GB.
pub const MAX_COORDINATES: usize = 1_000;

/// Top-level keys of a model file.
pub const TOP_LEVEL_KEYS: &[&str] = &[
    "name",
    "description",
    "units",
    "parameters",
    "coordinates",
    "kinetic",
    "potential",
    "generalized_forces",
    "points",
    "bodies",
    "gravity",
    "springs",
    "dampers",
    "forces",
    "torques",
    "initial",
    "draw",
    "balances",
    "checks",
    "constraints",
    "nonholonomic",
    "events",
    "equilibria",
    "floquet",
    "minimal_twin",
];

/// Keys of the model format that this version does not implement yet.
pub const LATER_KEYS: &[&str] = &["outputs"];

/// Keys of `checks:`.
pub const CHECK_KEYS: &[&str] = &[
    "equations_of_motion",
    "natural_frequencies",
    "damping_ratios",
    "period",
    "final_state",
    "conserved",
    "energy_drift",
    "constraint_drift",
];

const BODY_KEYS: &[&str] = &["mass", "at", "inertia", "com", "angle"];
const PARTICLE_EXAMPLE: &str = "{ mass: m, at: P }";
const RIGID_EXAMPLE: &str = "{ mass: m, inertia: m*l^2/12, com: G, angle: theta }";

/// What the schema pass built from a file, and what it had to leave out.
#[derive(Debug, Clone, PartialEq)]
pub struct Built {
    /// The typed model without the entries that had errors; `None` when the file is not a
    /// map of `key: value` at all.
    pub file: Option<ModelFile>,
    /// What was left out of `file` because of a reported error.
    pub incomplete: Incomplete,
    /// Every problem found, sorted by location.
    pub diagnostics: Vec<Diagnostic>,
}

/// Parts of a model that the schema pass left out because of an error it already reported.
///
/// The cross-object checks treat them as present, so that one mistake gives one message
/// (a point with a malformed position is not also an "unknown point" for the body at it).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Incomplete {
    /// Names of parameters, coordinates, points and bodies whose entries were left out.
    pub names: Vec<String>,
    /// Top-level keys with at least one reported error (including required keys that are
    /// missing).
    pub sections: Vec<String>,
}

impl Incomplete {
    /// Whether the entry called `name` was left out.
    pub fn has_name(&self, name: &str) -> bool {
        self.names.iter().any(|n| n == name)
    }

    /// Whether the top-level key `section` had an error.
    pub fn has_section(&self, section: &str) -> bool {
        self.sections.iter().any(|s| s == section)
    }
}

/// Builds the typed model from the YAML tree of `path`.
///
/// # Errors
/// Every schema diagnostic of the file, sorted by location.
pub fn build(path: &str, source: &str, root: &YamlNode) -> Result<ModelFile, Vec<Diagnostic>> {
    let built = build_partial(path, source, root);
    match built.file {
        Some(file) if built.diagnostics.is_empty() => Ok(file),
        _ => Err(built.diagnostics),
    }
}

/// Builds as much of the typed model as the YAML tree allows, with every diagnostic and a
/// record of what was left out (see [`Built`]).
pub fn build_partial(path: &str, source: &str, root: &YamlNode) -> Built {
    let mut cx = Ctx {
        source,
        lines: source.lines().collect(),
        diagnostics: Diagnostics::new(),
        incomplete: Incomplete::default(),
        section: "",
    };
    let file = cx.model(path, root);
    let diagnostics = cx.diagnostics.finish().err().unwrap_or_default();
    Built {
        file,
        incomplete: cx.incomplete,
        diagnostics,
    }
}

/// Where the text `comment` of the trailing comment of `line`, whose text is `text`, starts
/// (it ends the line).
fn comment_location(text: &str, line: u32, comment: &str) -> Location {
    let text = text.trim_end();
    let byte = text.len().saturating_sub(comment.len());
    let column = text.get(..byte).map_or(0, |p| p.chars().count());
    Location {
        line,
        column: column as u32 + 1,
    }
}

/// Whether `s` is a model-file name: a letter, then letters, digits and `_`.
pub fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    c.next().is_some_and(|f| f.is_ascii_alphabetic())
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

/// Rust's keywords, strict and reserved, of every edition up to 2024 (`gen`): generated code
/// spells a parameter or coordinate named so as a raw identifier (`r#type`).
pub const RUST_KEYWORDS: &[&str] = &[
    "as", "async", "await", "break", "const", "continue", "crate", "dyn", "else", "enum", "extern",
    "false", "fn", "for", "gen", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut",
    "pub", "ref", "return", "self", "Self", "static", "struct", "super", "trait", "true", "type",
    "unsafe", "use", "where", "while", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try",
];

/// The keywords that are not raw identifiers either (`r#self` is not Rust): no parameter or
/// coordinate can be named so, and no model whose struct ([`struct_name`]) would be `Self`.
pub const UNRAW_KEYWORDS: &[&str] = &["self", "Self", "super", "crate"];

/// The generated struct's name, the UpperCamelCase of the model's: `double_pendulum` →
/// `DoublePendulum`.
pub fn struct_name(model_name: &str) -> String {
    model_name
        .split('_')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let mut c = p.chars();
            match c.next() {
                Some(f) => f.to_ascii_uppercase().to_string() + c.as_str(),
                None => String::new(),
            }
        })
        .collect()
}

/// Whether `s` is a snake_case identifier: a lowercase letter, then lowercase letters,
/// digits and `_`.
pub fn is_snake_case(s: &str) -> bool {
    let mut c = s.chars();
    c.next().is_some_and(|f| f.is_ascii_lowercase())
        && c.all(|x| x.is_ascii_lowercase() || x.is_ascii_digit() || x == '_')
}

/// A snake_case spelling of `s` for suggestions (`DoublePendulum` → `double_pendulum`).
fn to_snake_case(s: &str) -> String {
    let mut out = String::new();
    let mut previous_lower = false;
    for c in s.chars() {
        if c.is_ascii_uppercase() {
            if previous_lower {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
            previous_lower = false;
        } else if c.is_ascii_alphanumeric() {
            out.push(c);
            previous_lower = true;
        } else {
            out.push('_');
            previous_lower = false;
        }
    }
    let mut collapsed = String::new();
    for c in out.chars() {
        if !(c == '_' && collapsed.ends_with('_')) {
            collapsed.push(c);
        }
    }
    let trimmed = collapsed.trim_matches('_');
    if trimmed.starts_with(|c: char| c.is_ascii_lowercase()) {
        trimmed.to_string()
    } else {
        format!("model_{trimmed}").trim_end_matches('_').to_string()
    }
}

fn get<'n>(entries: &'n Entries, key: &str) -> Option<&'n YamlNode> {
    entries.iter().find(|(k, _)| k.value == key).map(|(_, v)| v)
}

/// Whether `entries` has a key that is a misspelling of the missing key `key`: it is then
/// reported once, as an unknown key with "did you mean `key`?", not also as missing.
fn misspelt(entries: &Entries, key: &str) -> bool {
    entries
        .iter()
        .any(|(k, _)| k.value != key && closest(&k.value, &[key]).is_some())
}

fn get_key<'n>(entries: &'n Entries, key: &str) -> Option<&'n Located<String>> {
    entries.iter().find(|(k, _)| k.value == key).map(|(k, _)| k)
}

/// The keys present, for messages: `` `inertia`, `com` ``.
fn listed(entries: &Entries) -> String {
    if entries.is_empty() {
        return "nothing".to_string();
    }
    entries
        .iter()
        .map(|(k, _)| format!("`{}`", k.value))
        .collect::<Vec<_>>()
        .join(", ")
}

/// More `(` than `)`: an expression that may have been cut at a `,`.
fn opens_more_than_it_closes(text: &str) -> bool {
    text.matches('(').count() > text.matches(')').count()
}

/// Whether `text` closes a `(` it did not open: the rest of a cut expression.
fn closes_first(text: &str) -> bool {
    let mut depth = 0usize;
    for c in text.chars() {
        match c {
            '(' => depth += 1,
            ')' if depth == 0 => return true,
            ')' => depth -= 1,
            _ => {}
        }
    }
    false
}

/// Whether the source after `end` is `, …)`: YAML ended a value at a `,` of a flow collection
/// (`{ angle: atan2(y, x) }`) and the rest of the expression follows.
fn cut_in_source(source: &str, end: Location) -> bool {
    let Some(line) = source.lines().nth(end.line.saturating_sub(1) as usize) else {
        return false;
    };
    let byte = line
        .char_indices()
        .nth(end.column.saturating_sub(1) as usize)
        .map_or(line.len(), |(i, _)| i);
    let offset = source
        .lines()
        .take(end.line.saturating_sub(1) as usize)
        .map(|l| l.len() + 1)
        .sum::<usize>()
        + byte;
    let Some(rest) = source.get(offset..) else {
        return false;
    };
    let Some(after) = rest.trim_start().strip_prefix(',') else {
        return false;
    };
    let piece: String = after
        .chars()
        .take_while(|c| !matches!(c, ',' | ']' | '}'))
        .collect();
    closes_first(&piece)
}

struct Ctx<'s> {
    source: &'s str,
    /// The lines of `source`, looked up by number (1-based) with [`Ctx::line`].
    lines: Vec<&'s str>,
    diagnostics: Diagnostics,
    incomplete: Incomplete,
    /// The top-level key being read; every error marks it incomplete.
    section: &'static str,
}

impl<'s> Ctx<'s> {
    /// The text of line `line` (1-based) of the source, empty past its end.
    fn line(&self, line: u32) -> &'s str {
        line.checked_sub(1)
            .and_then(|i| self.lines.get(i as usize))
            .copied()
            .unwrap_or_default()
    }

    fn error(&mut self, d: Diagnostic) {
        self.diagnostics.push(d);
        if !self.section.is_empty() && !self.incomplete.has_section(self.section) {
            self.incomplete.sections.push(self.section.to_string());
        }
    }

    fn drop_name(&mut self, name: &str) {
        if !self.incomplete.has_name(name) {
            self.incomplete.names.push(name.to_string());
        }
    }

    /// Reports every key of `entries` that is not in `allowed`.
    fn unknown_keys(&mut self, entries: &Entries, what: &str, allowed: &[&str], listed: &[&str]) {
        for (k, _) in entries {
            if allowed.contains(&k.value.as_str()) {
                continue;
            }
            let d = Diagnostic::new(k.location, format!("unknown key `{}` in {what}", k.value));
            let d = match closest(&k.value, allowed) {
                Some(c) => d.with_help(format!(
                    "did you mean `{c}`? {what} takes: {}",
                    listed.join(", ")
                )),
                None => d.with_help(format!("{what} takes: {}", listed.join(", "))),
            };
            self.error(d);
        }
    }

    /// Reports every key of `required` missing from `entries`; `Ok` when none is missing.
    fn require(
        &mut self,
        entries: &Entries,
        at: Location,
        what: &str,
        required: &[&str],
        example: &str,
    ) -> bool {
        let mut complete = true;
        for r in required {
            if get(entries, r).is_none() {
                complete = false;
                if misspelt(entries, r) {
                    continue;
                }
                self.error(
                    Diagnostic::new(at, format!("{what} has no `{r}`")).with_help(format!(
                        "found {}; write it like `{example}`",
                        listed(entries)
                    )),
                );
            }
        }
        complete
    }

    fn map<'n>(&mut self, node: &'n YamlNode, what: &str, example: &str) -> Option<&'n Entries> {
        match &node.kind {
            YamlKind::Map(e) => Some(e),
            YamlKind::Null => Some(&[]),
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be a map, found {}", other.describe()),
                    )
                    .with_help(format!("write it like `{example}`")),
                );
                None
            }
        }
    }

    fn seq<'n>(&mut self, node: &'n YamlNode, what: &str, example: &str) -> Option<&'n [YamlNode]> {
        match &node.kind {
            YamlKind::Seq(items) => Some(items),
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be a list, found {}", other.describe()),
                    )
                    .with_help(format!("write it like `{example}`")),
                );
                None
            }
        }
    }

    fn text(&mut self, node: &YamlNode, what: &str, example: &str) -> Option<Located<String>> {
        match &node.kind {
            YamlKind::Scalar { text, .. } => Some(Located::new(text.clone(), node.location)),
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be text, found {}", other.describe()),
                    )
                    .with_help(format!("write it like `{example}`")),
                );
                None
            }
        }
    }

    /// A name (identifier) written as a value, such as the point of `at: P`.
    fn name(&mut self, node: &YamlNode, what: &str) -> Option<Located<String>> {
        let t = match &node.kind {
            YamlKind::Scalar { text, .. } => Located::new(text.trim().to_string(), node.location),
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be a name, found {}", other.describe()),
                    )
                    .with_help("a name starts with a letter and contains letters, digits and `_`"),
                );
                return None;
            }
        };
        if !is_identifier(&t.value) {
            self.error(
                Diagnostic::new(t.location, format!("{what} `{}` is not a name", t.value))
                    .with_help("a name starts with a letter and contains letters, digits and `_`"),
            );
            return None;
        }
        Some(t)
    }

    /// A name written as a key, such as a point's in `points: { P: … }`.
    fn key_name(&mut self, key: &Located<String>, what: &str) -> bool {
        if is_identifier(&key.value) {
            return true;
        }
        self.error(
            Diagnostic::new(
                key.location,
                format!("{what} `{}` is not a name", key.value),
            )
            .with_help("a name starts with a letter and contains letters, digits and `_`"),
        );
        false
    }

    /// An expression written as a scalar; its locations are exact even across lines.
    fn expr(&mut self, node: &YamlNode, what: &str) -> Option<Expr> {
        let text = self.scalar_expr_text(node, what)?;
        self.parse_part(node, &text, 0, text.chars().count())
    }

    /// The text of a scalar that should hold an expression; reports anything else.
    fn scalar_expr_text(&mut self, node: &YamlNode, what: &str) -> Option<String> {
        let text = match &node.kind {
            YamlKind::Scalar { text, .. } => text,
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("{what} must be an expression, found {}", other.describe()),
                    )
                    .with_help("write a number or an expression such as `m*g*l*cos(theta)`"),
                );
                return None;
            }
        };
        Some(text.clone())
    }

    /// Parses characters `from..to` of the scalar `node` (whose text is `text`) as an
    /// expression, with exact file locations.
    fn parse_part(&mut self, node: &YamlNode, text: &str, from: usize, to: usize) -> Option<Expr> {
        let start = node.location;
        let locations = char_locations_in_lines(&self.lines, start, text);
        let locate = |i: usize| match &locations {
            Some(l) => l.get(from + i).or(l.last()).copied().unwrap_or(start),
            None => start.offset(from + i),
        };
        let part: String = text.chars().skip(from).take(to - from).collect();
        match parse_expr_mapped(&part, &locate) {
            Ok(e) => Some(e),
            Err(d) => {
                let end = locate(part.chars().count());
                let cut = opens_more_than_it_closes(&part)
                    && !matches!(node.kind, YamlKind::Scalar { quoted: true, .. })
                    && cut_in_source(self.source, end);
                let d = if cut {
                    d.with_help(
                        "inside `[…]` or `{…}`, YAML splits values at every `,`: quote an expression that contains a `,`, as in `\"atan2(y, x)\"`",
                    )
                } else {
                    d
                };
                self.error(d);
                None
            }
        }
    }

    /// A list of 2 or 3 expressions.
    fn vector(&mut self, node: &YamlNode, what: &str, example: &str) -> Option<Vec<Expr>> {
        let items = match &node.kind {
            YamlKind::Seq(items) => items,
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!(
                            "{what} must be a list of 2 or 3 expressions, found {}",
                            other.describe()
                        ),
                    )
                    .with_help(format!("write it like `{example}`")),
                );
                return None;
            }
        };
        // `[atan2(y, x), 0]` reaches us as `atan2(y`, `x)`, `0`: say so rather than count.
        let cut = items
            .iter()
            .enumerate()
            .find(|(i, item)| {
                let unquoted = |n: &YamlNode| match &n.kind {
                    YamlKind::Scalar {
                        text,
                        quoted: false,
                    } => Some(text.clone()),
                    _ => None,
                };
                unquoted(item).is_some_and(|t| opens_more_than_it_closes(&t))
                    && items
                        .get(i + 1)
                        .and_then(unquoted)
                        .is_some_and(|t| closes_first(&t))
            })
            .map(|(_, item)| item);
        if let Some(item) = cut {
            self.error(
                Diagnostic::new(
                    item.location,
                    format!(
                        "{what}: {} is cut at a `,`",
                        item.kind.describe()
                    ),
                )
                .with_help(
                    "inside `[…]`, YAML splits values at every `,`: quote a component that contains a `,`, as in `\"atan2(y, x)\"`",
                ),
            );
            return None;
        }
        if !(2..=3).contains(&items.len()) {
            self.error(
                Diagnostic::new(
                    node.location,
                    format!(
                        "{what} has {} component{}; expected 2 (planar) or 3 (spatial)",
                        items.len(),
                        if items.len() == 1 { "" } else { "s" }
                    ),
                )
                .with_help(format!("write it like `{example}`")),
            );
            return None;
        }
        let out: Vec<Option<Expr>> = items.iter().map(|i| self.expr(i, what)).collect();
        out.into_iter().collect()
    }

    /// `[A, B]`: two point names.
    fn point_pair(&mut self, node: &YamlNode, what: &str) -> Option<[Located<String>; 2]> {
        let items = self.seq(node, what, "[A, B]")?;
        if items.len() != 2 {
            self.error(
                Diagnostic::new(
                    node.location,
                    format!("{what} must name two points, found {}", items.len()),
                )
                .with_help("write it like `[A, B]`"),
            );
            return None;
        }
        let a = self.name(&items[0], "a point");
        let b = self.name(&items[1], "a point");
        Some([a?, b?])
    }

    fn model(&mut self, path: &str, root: &YamlNode) -> Option<ModelFile> {
        let YamlKind::Map(top) = &root.kind else {
            self.error(
                Diagnostic::new(
                    root.location,
                    format!(
                        "a model file must be a map of `key: value`, found {}",
                        root.kind.describe()
                    ),
                )
                .with_help("start with `name: my_model` and `coordinates: [q]`"),
            );
            return None;
        };

        // Rule: keys planned for later versions are recognised and reported once each.
        for (k, _) in top {
            if LATER_KEYS.contains(&k.value.as_str()) {
                self.error(
                    Diagnostic::new(
                        k.location,
                        format!(
                            "`{}:` is not supported yet by this version of eomgen",
                            k.value
                        ),
                    )
                    .with_help("it is planned; remove it for now"),
                );
            }
        }
        let allowed: Vec<&str> = TOP_LEVEL_KEYS.iter().chain(LATER_KEYS).copied().collect();
        self.unknown_keys(top, "a model file", &allowed, TOP_LEVEL_KEYS);

        self.section = "name";
        let name = match get(top, "name") {
            None if misspelt(top, "name") => None,
            None => {
                self.error(
                    Diagnostic::new(root.location, "the model file has no `name`").with_help(
                        "add `name: my_model` (snake_case; the generated struct is `MyModel`)",
                    ),
                );
                None
            }
            Some(n) => self.name(n, "`name`").and_then(|n| {
                if is_snake_case(&n.value) {
                    Some(n)
                } else {
                    let d = Diagnostic::new(
                        n.location,
                        format!("`name` must be snake_case, found `{}`", n.value),
                    )
                    .with_help(format!(
                        "write `name: {}`; the generated struct takes its UpperCamelCase form",
                        to_snake_case(&n.value)
                    ));
                    self.error(d);
                    None
                }
            }),
        }
        .unwrap_or_else(|| Located::new(String::new(), root.location));

        self.section = "description";
        let description = match get(top, "description") {
            None => String::new(),
            Some(YamlNode {
                kind: YamlKind::Null,
                ..
            }) => String::new(),
            // A folded (`>`) description ends with a line break; keep the text only.
            Some(n) => self
                .text(n, "`description`", "description: A pendulum of length l.")
                .map(|d| d.value.trim().to_string())
                .unwrap_or_default(),
        };

        self.section = "minimal_twin";
        let minimal_twin = get(top, "minimal_twin")
            .and_then(|n| self.name(n, "`minimal_twin`"))
            .and_then(|twin| self.minimal_twin(twin, &name));

        self.section = "units";
        let units = get(top, "units").and_then(|n| {
            self.choice(n, "`units`", &[("SI", UnitSystem::Si)])
                .map(|u| Located::new(u, n.location))
        });

        self.section = "parameters";
        let parameters = get(top, "parameters")
            .map(|n| self.parameters(n))
            .unwrap_or_default();
        self.section = "coordinates";
        let coordinates = match get(top, "coordinates") {
            Some(n) => self.coordinates(n),
            None if misspelt(top, "coordinates") => {
                self.incomplete.sections.push("coordinates".to_string());
                Vec::new()
            }
            None => {
                self.error(
                    Diagnostic::new(root.location, "the model file has no `coordinates`")
                        .with_help("list the generalized coordinates: `coordinates: [theta]`"),
                );
                Vec::new()
            }
        };

        self.section = "kinetic";
        let kinetic = get(top, "kinetic").and_then(|n| self.expr(n, "`kinetic`"));
        self.section = "potential";
        let potential = get(top, "potential").and_then(|n| self.expr(n, "`potential`"));
        self.section = "generalized_forces";
        let generalized_forces = get(top, "generalized_forces")
            .map(|n| {
                self.keyed_exprs(
                    n,
                    "`generalized_forces`",
                    "generalized_forces: { x: -c*x_dot }",
                    "a generalized force",
                )
            })
            .unwrap_or_default();

        self.section = "points";
        let points = get(top, "points")
            .map(|n| self.points(n))
            .unwrap_or_default();
        self.section = "bodies";
        let bodies = get(top, "bodies")
            .map(|n| self.bodies(n))
            .unwrap_or_default();
        self.section = "gravity";
        let gravity = get(top, "gravity").and_then(|n| {
            self.vector(n, "`gravity`", "gravity: [0, -g]")
                .map(|g| Located::new(g, n.location))
        });
        self.section = "springs";
        let springs = get(top, "springs")
            .map(|n| self.springs(n))
            .unwrap_or_default();
        self.section = "dampers";
        let dampers = get(top, "dampers")
            .map(|n| self.dampers(n))
            .unwrap_or_default();
        self.section = "forces";
        let forces = get(top, "forces")
            .map(|n| self.forces(n))
            .unwrap_or_default();
        self.section = "torques";
        let torques = get(top, "torques")
            .map(|n| self.torques(n))
            .unwrap_or_default();
        self.section = "constraints";
        let constraints = get(top, "constraints")
            .map(|n| {
                self.keyed_exprs(
                    n,
                    "`constraints`",
                    "constraints: { rod: sqrt(x^2 + y^2) - l }",
                    "a holonomic constraint",
                )
            })
            .unwrap_or_default();
        self.section = "nonholonomic";
        let nonholonomic = get(top, "nonholonomic")
            .map(|n| {
                self.keyed_exprs(
                    n,
                    "`nonholonomic`",
                    "nonholonomic: { no_side_slip: -sin(theta)*x_dot + cos(theta)*y_dot }",
                    "a non-holonomic constraint",
                )
            })
            .unwrap_or_default();
        self.section = "initial";
        let (initial, initial_guesses) = get(top, "initial")
            .map(|n| self.initial(n))
            .unwrap_or_default();
        self.section = "draw";
        let draw = get(top, "draw").map(|n| self.draw(n)).unwrap_or_default();
        self.section = "balances";
        let balances = get(top, "balances")
            .map(|n| self.balances(n))
            .unwrap_or_default();
        self.section = "checks";
        let checks = get(top, "checks")
            .map(|n| self.checks(n))
            .unwrap_or_default();
        self.section = "events";
        let events = get(top, "events")
            .map(|n| self.events(n))
            .unwrap_or_default();
        self.section = "equilibria";
        let equilibria = get(top, "equilibria")
            .map(|n| self.equilibria(n))
            .unwrap_or_default();
        self.section = "floquet";
        let floquet = get(top, "floquet")
            .map(|n| self.floquet(n))
            .unwrap_or_default();
        self.section = "";

        let dimension = points.first().map(|p: &Point| p.position.len());
        Some(ModelFile {
            path: path.to_string(),
            name,
            description,
            minimal_twin,
            units,
            parameters,
            coordinates,
            kinetic,
            potential,
            generalized_forces,
            points,
            bodies,
            gravity,
            springs,
            dampers,
            forces,
            torques,
            initial,
            draw,
            dimension,
            balances,
            checks,
            constraints,
            nonholonomic,
            initial_guesses,
            events,
            equilibria,
            floquet,
        })
    }

    /// `floquet:` — `equilibrium: { axis_units: { p: unit }, thresholds: { name: { … } },
    /// curves: { name: { … } } }`.
    fn floquet(&mut self, node: &YamlNode) -> Vec<FloquetReference> {
        const EXAMPLE: &str = "{ axis_units: { a: m }, curves: { kapitza: { label: Kapitza, color: [0, 0, 0], along: a, gives: w, value: sqrt(2*g*l)/a } } }";
        let Some(entries) = self.map(
            node,
            "`floquet`",
            &format!("floquet: {{ upright: {EXAMPLE} }}"),
        ) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            if !self.key_name(k, "equilibrium") {
                continue;
            }
            let Some(f) = self.fields(
                k,
                v,
                "the Floquet references at",
                &["axis_units", "thresholds", "curves"],
                &[],
                EXAMPLE,
            ) else {
                continue;
            };
            let axis_units = get(f, "axis_units")
                .and_then(|n| self.map(n, "`axis_units`", "axis_units: { a: m, w: rad/s }"))
                .map(|units| {
                    units
                        .iter()
                        .filter_map(|(p, u)| {
                            let u = self.text(u, &format!("the unit of `{}`", p.value), "m")?;
                            Some((p.clone(), u))
                        })
                        .collect()
                })
                .unwrap_or_default();
            let thresholds = get(f, "thresholds")
                .map(|n| self.floquet_thresholds(n))
                .unwrap_or_default();
            let curves = get(f, "curves")
                .map(|n| self.reference_curves(n))
                .unwrap_or_default();
            out.push(FloquetReference {
                at: k.clone(),
                axis_units,
                thresholds,
                curves,
            });
        }
        out
    }

    /// `thresholds:` of a `floquet:` entry.
    fn floquet_thresholds(&mut self, node: &YamlNode) -> Vec<FloquetThreshold> {
        const EXAMPLE: &str = "{ key: a_w, label: a w, value: a*w, critical: sqrt(2*g*l), critical_label: √(2 g l), by: averaging, note: for a ≪ l }";
        let Some(entries) = self.map(
            node,
            "`thresholds`",
            &format!("thresholds: {{ kapitza: {EXAMPLE} }}"),
        ) else {
            return Vec::new();
        };
        let keys = [
            "key",
            "label",
            "value",
            "critical",
            "critical_label",
            "by",
            "note",
        ];
        let mut out = Vec::new();
        for (k, v) in entries {
            if !self.key_name(k, "threshold") {
                continue;
            }
            let Some(f) = self.fields(k, v, "threshold", &keys, &keys, EXAMPLE) else {
                continue;
            };
            let what = |field: &str| format!("`{field}` of threshold `{}`", k.value);
            let key = get(f, "key").and_then(|n| self.name(n, &what("key")));
            let mut texts = ["label", "critical_label", "by", "note"]
                .map(|field| get(f, field).and_then(|n| self.text(n, &what(field), "a w")));
            let value = get(f, "value").and_then(|n| self.expr(n, &what("value")));
            let critical = get(f, "critical").and_then(|n| self.expr(n, &what("critical")));
            let [Some(label), Some(critical_label), Some(by), Some(note)] =
                texts.each_mut().map(Option::take)
            else {
                continue;
            };
            let (Some(key), Some(value), Some(critical)) = (key, value, critical) else {
                continue;
            };
            out.push(FloquetThreshold {
                name: k.clone(),
                key,
                label: label.value,
                value,
                critical,
                critical_label: critical_label.value,
                by: by.value,
                note: note.value,
            });
        }
        out
    }

    /// `curves:` of a `floquet:` entry.
    fn reference_curves(&mut self, node: &YamlNode) -> Vec<ReferenceCurve> {
        const EXAMPLE: &str =
            "{ label: Kapitza, color: [0, 0, 0], along: a, gives: w, value: sqrt(2*g*l)/a }";
        let Some(entries) = self.map(
            node,
            "`curves`",
            &format!("curves: {{ kapitza: {EXAMPLE} }}"),
        ) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            if !self.key_name(k, "curve") {
                continue;
            }
            let Some(f) = self.fields(
                k,
                v,
                "curve",
                &["label", "color", "along", "gives", "value", "where"],
                &["label", "color", "along", "gives", "value"],
                EXAMPLE,
            ) else {
                continue;
            };
            let what = |field: &str| format!("`{field}` of curve `{}`", k.value);
            let label = get(f, "label").and_then(|n| self.text(n, &what("label"), "Kapitza"));
            let color = get(f, "color").and_then(|n| {
                let items = self.seq(n, &what("color"), "color: [0, 150, 60]")?;
                if items.len() != 3 {
                    self.error(
                        Diagnostic::new(
                            n.location,
                            format!("{} has {} entries, not 3", what("color"), items.len()),
                        )
                        .with_help(
                            "write red, green and blue from 0 to 255: `color: [0, 150, 60]`",
                        ),
                    );
                    return None;
                }
                items
                    .iter()
                    .map(|c| self.expr(c, &what("color")))
                    .collect::<Option<Vec<Expr>>>()
            });
            let along = get(f, "along").and_then(|n| self.name(n, &what("along")));
            let gives = get(f, "gives").and_then(|n| self.name(n, &what("gives")));
            let value = get(f, "value").and_then(|n| self.expr(n, &what("value")));
            let domain = get(f, "where").and_then(|n| self.expr(n, &what("where")));
            let (Some(label), Some(color), Some(along), Some(gives), Some(value)) =
                (label, color, along, gives, value)
            else {
                continue;
            };
            out.push(ReferenceCurve {
                name: k.clone(),
                label: label.value,
                color,
                along,
                gives,
                value,
                domain,
            });
        }
        out
    }

    /// `minimal_twin:` — the snake_case name of another model, the same mechanism in minimal
    /// coordinates. Rule: it is a snake_case name (a bundled model's) and not the model's own.
    fn minimal_twin(
        &mut self,
        twin: Located<String>,
        name: &Located<String>,
    ) -> Option<Located<String>> {
        if !is_snake_case(&twin.value) {
            let d = Diagnostic::new(
                twin.location,
                format!(
                    "`minimal_twin` must be the snake_case name of a bundled model, found `{}`",
                    twin.value
                ),
            )
            .with_help("write `minimal_twin: simple_pendulum` (see `eomgen list`)");
            self.error(d);
            return None;
        }
        if twin.value == name.value {
            let d = Diagnostic::new(
                twin.location,
                format!("`minimal_twin` names the model itself, `{}`", twin.value),
            )
            .with_help("name the model with the same mechanism in minimal coordinates, or leave the key out");
            self.error(d);
            return None;
        }
        Some(twin)
    }

    /// `equilibria:` — `name: { coordinate: value, … }`.
    fn equilibria(&mut self, node: &YamlNode) -> Vec<EquilibriumDef> {
        const EXAMPLE: &str = "equilibria: { hanging: { theta: 0 }, upright: { theta: pi } }";
        let Some(entries) = self.map(node, "`equilibria`", EXAMPLE) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            if !self.key_name(k, "equilibrium") {
                continue;
            }
            let what = format!("equilibrium `{}`", k.value);
            let Some(values) = self.map(v, &what, &format!("{}: {{ theta: pi }}", k.value)) else {
                continue;
            };
            let values = values
                .iter()
                .filter_map(|(c, e)| {
                    let e = self.expr(e, &format!("the value of `{}` in {what}", c.value))?;
                    Some((c.clone(), e))
                })
                .collect();
            out.push(EquilibriumDef {
                name: k.clone(),
                values,
            });
        }
        out
    }

    /// `events:` — `name: g` or `name: { when: g, direction: rising|falling|both,
    /// terminal: true|false }`, where `g` is an expression (the event is `g = 0`) or an
    /// equation `lhs = rhs`.
    fn events(&mut self, node: &YamlNode) -> Vec<EventDef> {
        const EXAMPLE: &str = "{ when: theta_dot, direction: falling, terminal: false }";
        let Some(entries) = self.map(node, "`events`", &format!("events: {{ peak: {EXAMPLE} }}"))
        else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            if !self.key_name(k, "event") {
                continue;
            }
            let what = format!("the function of event `{}`", k.value);
            if !matches!(v.kind, YamlKind::Map(_)) {
                if let Some(when) = self.event_function(v, &what) {
                    out.push(EventDef {
                        name: k.clone(),
                        when,
                        direction: Crossing::Both,
                        terminal: false,
                    });
                }
                continue;
            }
            let Some(f) = self.fields(
                k,
                v,
                "event",
                &["when", "direction", "terminal"],
                &["when"],
                EXAMPLE,
            ) else {
                continue;
            };
            let when = get(f, "when").and_then(|n| self.event_function(n, &what));
            let direction = match get(f, "direction") {
                None => Some(Crossing::Both),
                Some(n) => self.choice(
                    n,
                    &format!("the direction of event `{}`", k.value),
                    &[
                        ("rising", Crossing::Rising),
                        ("falling", Crossing::Falling),
                        ("both", Crossing::Both),
                    ],
                ),
            };
            let terminal = match get(f, "terminal") {
                None => Some(false),
                Some(n) => self.choice(
                    n,
                    &format!("`terminal` of event `{}`", k.value),
                    &[("true", true), ("false", false)],
                ),
            };
            if let (Some(when), Some(direction), Some(terminal)) = (when, direction, terminal) {
                out.push(EventDef {
                    name: k.clone(),
                    when,
                    direction,
                    terminal,
                });
            }
        }
        out
    }

    /// One of a few words, as a scalar; an error lists them (with a "did you mean").
    fn choice<T: Copy>(&mut self, node: &YamlNode, what: &str, options: &[(&str, T)]) -> Option<T> {
        let words: Vec<&str> = options.iter().map(|(w, _)| *w).collect();
        let text = match &node.kind {
            YamlKind::Scalar { text, .. } => text.trim(),
            _ => "",
        };
        if let Some((_, value)) = options.iter().find(|(w, _)| *w == text) {
            return Some(*value);
        }
        let help = match closest(text, &words) {
            Some(c) if !text.is_empty() => format!("did you mean `{c}`?"),
            _ => format!("write one of: {}", words.join(", ")),
        };
        self.error(
            Diagnostic::new(
                node.location,
                format!(
                    "{what} must be one of {}, found {}",
                    words.join(", "),
                    node.kind.describe()
                ),
            )
            .with_help(help),
        );
        None
    }

    /// `initial:` — values, or `{ guess: value }` for coordinates solved from the constraints.
    fn initial(&mut self, node: &YamlNode) -> (KeyedExprs, Vec<Located<String>>) {
        let Some(entries) = self.map(node, "`initial`", "initial: { theta: pi/2, theta_dot: 0 }")
        else {
            return Default::default();
        };
        let mut values = Vec::new();
        let mut guesses = Vec::new();
        for (k, v) in entries {
            let what = format!("an initial value (`{}`)", k.value);
            if let YamlKind::Map(inner) = &v.kind {
                if inner.len() == 1 && inner[0].0.value == "guess" {
                    if let Some(e) = self.expr(&inner[0].1, &what) {
                        values.push((k.clone(), e));
                        guesses.push(k.clone());
                    }
                } else {
                    self.error(
                        Diagnostic::new(v.location, format!("{what} is an expression or `{{ guess: value }}`"))
                            .with_help("`{ guess: 0.5 }` marks a starting guess that the runtime corrects to satisfy the constraints"),
                    );
                }
            } else if let Some(e) = self.expr(v, &what) {
                values.push((k.clone(), e));
            }
        }
        (values, guesses)
    }

    fn checks(&mut self, node: &YamlNode) -> Checks {
        const EXAMPLE: &str =
            "checks:\n  natural_frequencies: { at: hanging, values: [sqrt(g/l)] }";
        let mut checks = Checks::default();
        let Some(entries) = self.map(node, "`checks`", EXAMPLE) else {
            return checks;
        };
        self.unknown_keys(entries, "`checks`", CHECK_KEYS, CHECK_KEYS);
        if let Some(list) = get(entries, "equations_of_motion").and_then(|n| {
            self.seq(
                n,
                "`equations_of_motion`",
                "equations_of_motion: [m*x_ddot + k*x = 0]",
            )
        }) {
            for item in list {
                if let Some(e) = self.equation(item) {
                    checks.equations_of_motion.push(e);
                }
            }
        }
        for (k, v) in entries {
            match k.value.as_str() {
                "natural_frequencies" => checks.natural_frequencies = self.modal_check(k, v),
                "damping_ratios" => checks.damping_ratios = self.modal_check(k, v),
                "period" => checks.period = self.period_check(k, v),
                "final_state" => checks.final_state = self.final_state_check(k, v),
                "conserved" => checks.conserved = self.conserved_checks(v),
                "energy_drift" => {
                    checks.energy_drift = self.drift_check(k, v, DEFAULT_ENERGY_DRIFT)
                }
                "constraint_drift" => {
                    checks.constraint_drift = self.drift_check(k, v, DEFAULT_CONSTRAINT_DRIFT)
                }
                _ => {}
            }
        }
        checks
    }

    /// A positive finite number written as a plain scalar (`1e-9`).
    fn positive_number(&mut self, node: &YamlNode, what: &str) -> Option<f64> {
        let value = match &node.kind {
            YamlKind::Scalar { text, .. } => text.trim().parse::<f64>().ok(),
            _ => None,
        };
        match value {
            Some(v) if v.is_finite() && v > 0.0 => Some(v),
            _ => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!(
                            "{what} must be a positive number, found {}",
                            node.kind.describe()
                        ),
                    )
                    .with_help("write a number such as `1e-9`"),
                );
                None
            }
        }
    }

    /// The optional positive number `key` of `f`, `default` when absent.
    fn number_or(&mut self, f: &Entries, key: &str, what: &str, default: f64) -> Option<f64> {
        match get(f, key) {
            None => Some(default),
            Some(n) => self.positive_number(n, &format!("`{key}` of {what}")),
        }
    }

    /// `method:`, `rtol:` and `t_end:` of a check, each optional.
    fn run_settings(&mut self, f: &Entries, what: &str) -> Option<RunSettings> {
        let method = match get(f, "method") {
            None => Some(None),
            Some(n) => {
                let options: Vec<(&str, usize)> = CHECK_METHODS
                    .iter()
                    .enumerate()
                    .map(|(i, m)| (*m, i))
                    .collect();
                self.choice(n, &format!("`method` of {what}"), &options)
                    .map(|i| Some(Located::new(CHECK_METHODS[i].to_string(), n.location)))
            }
        };
        let rtol = match get(f, "rtol") {
            None => Some(None),
            Some(n) => self
                .positive_number(n, &format!("`rtol` of {what}"))
                .map(Some),
        };
        let t_end = match get(f, "t_end") {
            None => Some(None),
            Some(n) => self
                .positive_number(n, &format!("`t_end` of {what}"))
                .map(Some),
        };
        Some(RunSettings {
            method: method?,
            rtol: rtol?,
            t_end: t_end?,
        })
    }

    /// A list of expressions.
    fn expr_list(&mut self, node: &YamlNode, what: &str, example: &str) -> Option<Vec<Expr>> {
        let items = self.seq(node, what, example)?;
        let mut out = Vec::with_capacity(items.len());
        let mut complete = true;
        for item in items {
            match self.expr(item, &format!("a value of {what}")) {
                Some(e) => out.push(e),
                None => complete = false,
            }
        }
        complete.then_some(out)
    }

    /// `natural_frequencies:` or `damping_ratios:` — `{ at, values, tolerance }`.
    fn modal_check(&mut self, k: &Located<String>, v: &YamlNode) -> Option<ModalCheck> {
        let what = format!("check `{}`", k.value);
        let f = self.fields(
            k,
            v,
            "check",
            &["at", "values", "tolerance"],
            &["values"],
            "{ at: hanging, values: [sqrt(g/l)], tolerance: 1e-9 }",
        )?;
        let at = match get(f, "at") {
            None => Some(None),
            Some(n) => self.name(n, &format!("`at` of {what}")).map(Some),
        };
        let values = get(f, "values")
            .and_then(|n| self.expr_list(n, &format!("`values` of {what}"), "values: [sqrt(g/l)]"));
        let tolerance = self.number_or(f, "tolerance", &what, DEFAULT_CHECK_TOLERANCE);
        Some(ModalCheck {
            at: at?,
            values: values?,
            tolerance: tolerance?,
            location: k.location,
        })
    }

    /// `period:` — `{ event, value, tolerance, method, rtol, t_end }`.
    fn period_check(&mut self, k: &Located<String>, v: &YamlNode) -> Option<PeriodCheck> {
        let what = format!("check `{}`", k.value);
        let f = self.fields(
            k,
            v,
            "check",
            &["event", "value", "tolerance", "method", "rtol", "t_end"],
            &["event", "value"],
            "{ event: return, value: 2*pi*sqrt(l/g), tolerance: 1e-9 }",
        )?;
        let event = get(f, "event").and_then(|n| self.name(n, &format!("`event` of {what}")));
        let value = get(f, "value").and_then(|n| self.expr(n, &format!("`value` of {what}")));
        let tolerance = self.number_or(f, "tolerance", &what, DEFAULT_CHECK_TOLERANCE);
        let run = self.run_settings(f, &what);
        Some(PeriodCheck {
            event: event?,
            value: value?,
            tolerance: tolerance?,
            run: run?,
            location: k.location,
        })
    }

    /// `final_state:` — `{ t, values: { x: …, x_dot: … }, tolerance, method, rtol }`.
    fn final_state_check(&mut self, k: &Located<String>, v: &YamlNode) -> Option<FinalStateCheck> {
        let what = format!("check `{}`", k.value);
        let f = self.fields(
            k,
            v,
            "check",
            &["t", "values", "tolerance", "method", "rtol"],
            &["t", "values"],
            "{ t: 2, values: { x: 1, x_dot: 0 }, tolerance: 1e-9 }",
        )?;
        let t = get(f, "t").and_then(|n| self.expr(n, &format!("`t` of {what}")));
        let values = get(f, "values").and_then(|n| {
            self.keyed_exprs(
                n,
                &format!("`values` of {what}"),
                "values: { x: 1, x_dot: 0 }",
                "an expected value",
            )
            .into()
        });
        let tolerance = self.number_or(f, "tolerance", &what, DEFAULT_CHECK_TOLERANCE);
        let run = self.run_settings(f, &what);
        Some(FinalStateCheck {
            t: t?,
            values: values?,
            tolerance: tolerance?,
            run: run?,
            location: k.location,
        })
    }

    /// `conserved:` — `name: expr` or `name: { value: expr, tolerance: 1e-9 }`.
    fn conserved_checks(&mut self, node: &YamlNode) -> Vec<ConservedCheck> {
        const EXAMPLE: &str = "conserved: { momentum: (m1 + m2)*x_dot }";
        let Some(entries) = self.map(node, "`conserved`", EXAMPLE) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            if !self.key_name(k, "conserved quantity") {
                continue;
            }
            let what = format!("conserved quantity `{}`", k.value);
            if !matches!(v.kind, YamlKind::Map(_)) {
                if let Some(value) = self.expr(v, &what) {
                    out.push(ConservedCheck {
                        name: k.clone(),
                        value,
                        tolerance: DEFAULT_CHECK_TOLERANCE,
                    });
                }
                continue;
            }
            let Some(f) = self.fields(
                k,
                v,
                "conserved quantity",
                &["value", "tolerance"],
                &["value"],
                "{ value: m*x_dot, tolerance: 1e-9 }",
            ) else {
                continue;
            };
            let value = get(f, "value").and_then(|n| self.expr(n, &what));
            let tolerance = self.number_or(f, "tolerance", &what, DEFAULT_CHECK_TOLERANCE);
            if let (Some(value), Some(tolerance)) = (value, tolerance) {
                out.push(ConservedCheck {
                    name: k.clone(),
                    value,
                    tolerance,
                });
            }
        }
        out
    }

    /// `energy_drift:` or `constraint_drift:` — `{ max, method, rtol, t_end }`.
    fn drift_check(
        &mut self,
        k: &Located<String>,
        v: &YamlNode,
        default: f64,
    ) -> Option<DriftCheck> {
        let what = format!("check `{}`", k.value);
        let f = self.fields(
            k,
            v,
            "check",
            &["max", "method", "rtol", "t_end"],
            &[],
            "{ max: 1e-9, method: dop853, rtol: 1e-12, t_end: 10 }",
        )?;
        let max = self.number_or(f, "max", &what, default);
        let run = self.run_settings(f, &what);
        Some(DriftCheck {
            max: max?,
            run: run?,
            location: k.location,
        })
    }

    /// One `lhs = rhs` equation (or an expression meaning `= 0`).
    fn equation(&mut self, node: &YamlNode) -> Option<HandEquation> {
        let (lhs, rhs) = self.sides(
            node,
            "an equation of motion",
            "write one equation per entry, such as `m*x_ddot + k*x = F`",
        )?;
        Some(HandEquation {
            lhs,
            rhs,
            location: node.location,
        })
    }

    /// The two sides of `lhs = rhs` in the scalar `node`, or the expression alone (`rhs`
    /// `None`) when it has no `=`. `what` names the value and `help` says what to write when
    /// it has two `=`.
    fn sides(&mut self, node: &YamlNode, what: &str, help: &str) -> Option<(Expr, Option<Expr>)> {
        let text = self.scalar_expr_text(node, what)?;
        let chars: Vec<char> = text.chars().collect();
        let equals: Vec<usize> = (0..chars.len()).filter(|&i| chars[i] == '=').collect();
        match equals.as_slice() {
            [] => Some((self.parse_part(node, &text, 0, chars.len())?, None)),
            [i] => {
                let lhs = self.parse_part(node, &text, 0, *i);
                let rhs = self.parse_part(node, &text, i + 1, chars.len());
                Some((lhs?, Some(rhs?)))
            }
            [_, second, ..] => {
                let start = node.location;
                let at = char_locations_in_lines(&self.lines, start, &text)
                    .and_then(|l| l.get(*second).copied())
                    .unwrap_or_else(|| start.offset(*second));
                self.error(
                    Diagnostic::new(at, format!("{what} has one `=`, this is a second"))
                        .with_help(help),
                );
                None
            }
        }
    }

    /// The function of an event: an expression `g` (the event is `g = 0`), or an equation
    /// `lhs = rhs`, which means `lhs − rhs = 0` (as `--stop-when "y = 0"` on the command line).
    fn event_function(&mut self, node: &YamlNode, what: &str) -> Option<Expr> {
        let (lhs, rhs) = self.sides(
            node,
            what,
            "write the event as one expression that crosses zero, such as `y` or `x = l`",
        )?;
        Some(match rhs {
            None => lhs,
            // The `=` is not kept: the difference is located at its right side.
            Some(rhs) => Expr {
                location: lhs.location,
                kind: ExprKind::Binary {
                    op: BinOp::Sub,
                    op_location: rhs.location,
                    lhs: Box::new(lhs),
                    rhs: Box::new(rhs),
                },
            },
        })
    }

    fn balances(&mut self, node: &YamlNode) -> Vec<Balance> {
        const EXAMPLE: &str = "balances:\n  - { amb: { about: O, bodies: [upper, fore] } }\n  - { lmb: { bodies: [slider], along: [cos(theta), sin(theta)] } }";
        let Some(items) = self.seq(node, "`balances`", EXAMPLE) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for item in items {
            let Some(entries) = self.map(
                item,
                "a balance",
                "{ amb: { about: O, bodies: [upper, fore] } }",
            ) else {
                continue;
            };
            if entries.len() != 1 || !matches!(entries[0].0.value.as_str(), "amb" | "lmb") {
                self.error(
                    Diagnostic::new(item.location, "a balance is one of `amb: {…}` (angular momentum balance) or `lmb: {…}` (linear momentum balance)")
                        .with_help("write `{ amb: { about: O, bodies: [upper, fore] } }` or `{ lmb: { bodies: [slider], along: [1, 0] } }`"),
                );
                continue;
            }
            let (key, value) = &entries[0];
            let amb = key.value == "amb";
            let (allowed, example): (&[&str], &str) = if amb {
                (
                    &["about", "bodies", "form"],
                    "{ about: O, bodies: [upper, fore] }",
                )
            } else {
                (
                    &["bodies", "along"],
                    "{ bodies: [slider], along: [cos(theta), sin(theta)] }",
                )
            };
            let Some(f) = self.fields(
                key,
                value,
                if amb {
                    "angular momentum balance"
                } else {
                    "linear momentum balance"
                },
                allowed,
                &allowed[..2],
                example,
            ) else {
                continue;
            };
            let mut bodies = Vec::new();
            if let Some(list) =
                get(f, "bodies").and_then(|n| self.seq(n, "`bodies`", "bodies: [upper, fore]"))
            {
                for b in list {
                    if let Some(name) = self.name(b, "a body") {
                        bodies.push(name);
                    }
                }
            }
            let kind = if amb {
                let form = match get(f, "form") {
                    None => Some(AmbForm::RCrossMa),
                    Some(n) => match &n.kind {
                        YamlKind::Scalar { text, .. } if text == "r_x_ma" => {
                            Some(AmbForm::RCrossMa)
                        }
                        YamlKind::Scalar { text, .. } if text == "h_dot" => Some(AmbForm::HDot),
                        _ => {
                            self.error(
                                Diagnostic::new(n.location, "`form` of an angular momentum balance is `r_x_ma` or `h_dot`")
                                    .with_help("`r_x_ma` (the default): Σ M_A = Σ r_G/A × m a_G + I θ̈, valid about any point; `h_dot`: Σ M_A = dH_A/dt, valid about a fixed point or the centre of mass"),
                            );
                            None
                        }
                    },
                };
                get(f, "about")
                    .and_then(|n| self.name(n, "`about`"))
                    .zip(form)
                    .map(|(about, form)| BalanceKind::Amb { about, form })
            } else {
                get(f, "along")
                    .and_then(|n| self.vector(n, "`along`", "along: [cos(theta), sin(theta)]"))
                    .map(|along| BalanceKind::Lmb { along })
            };
            if let Some(kind) = kind
                && !bodies.is_empty()
            {
                out.push(Balance {
                    kind,
                    bodies,
                    location: item.location,
                });
            }
        }
        out
    }

    fn parameters(&mut self, node: &YamlNode) -> Vec<Parameter> {
        let Some(entries) = self.map(node, "`parameters`", "parameters: { m: 1.0, g: 9.81 }")
        else {
            return Vec::new();
        };
        // How many entries are written on each line (an entry counts once for each line its
        // key and value are on): counted once, so that the whole section is linear in its
        // number of parameters.
        let mut per_line: HashMap<u32, usize> = HashMap::new();
        for (k, v) in entries {
            *per_line.entry(k.location.line).or_default() += 1;
            if v.location.line != k.location.line {
                *per_line.entry(v.location.line).or_default() += 1;
            }
        }
        let mut out = Vec::new();
        for (k, v) in entries {
            if !self.key_name(k, "parameter") {
                continue;
            }
            if let Some(p) = self.parameter(k, v, &per_line) {
                out.push(p);
            } else {
                self.drop_name(&k.value);
            }
        }
        out
    }

    fn parameter(
        &mut self,
        k: &Located<String>,
        v: &YamlNode,
        per_line: &HashMap<u32, usize>,
    ) -> Option<Parameter> {
        // The map form `{ value: 1.0, unit: N/m }`.
        let mut unit_key = None;
        let v = if let YamlKind::Map(_) = &v.kind {
            let f = self.fields(
                k,
                v,
                "parameter",
                &["value", "unit"],
                &["value"],
                "{ value: 1.0, unit: kg }",
            )?;
            if let Some(u) = get(f, "unit") {
                let what = format!("the unit of parameter `{}`", k.value);
                unit_key = Some(self.text(u, &what, "unit: N/m")?);
            }
            get(f, "value")?
        } else {
            v
        };
        if v.kind == YamlKind::Null {
            self.error(
                Diagnostic::new(
                    k.location,
                    format!("parameter `{}` has no default value", k.value),
                )
                .with_help(format!("give one, as in `{}: 1.0  # kg`", k.value)),
            );
            return None;
        }
        let default = self.expr(v, &format!("the default of parameter `{}`", k.value))?;
        // Rule: parameter defaults are constant (numbers, `pi`, functions); they may not
        // refer to other parameters, coordinates or `t`.
        let mut names = Vec::new();
        identifiers(&default, &mut names);
        if let Some((n, at)) = names.into_iter().find(|(n, _)| n != "pi") {
            self.error(
                Diagnostic::new(
                    at,
                    format!(
                        "parameter defaults must be constant, but the default of `{}` uses `{n}`",
                        k.value
                    ),
                )
                .with_help("use numbers, `pi` and functions of them, as in `9.81`, `pi/4` or `sqrt(2)`; a default cannot refer to another parameter or a coordinate"),
            );
            return None;
        }
        let value = match eval_expr(&default, &|_| None) {
            Ok(value) => value,
            Err(d) => {
                self.error(d);
                return None;
            }
        };
        if !value.is_finite() {
            self.error(
                Diagnostic::new(
                    v.location,
                    format!(
                        "parameter `{}` has the non-finite default `{value}`",
                        k.value
                    ),
                )
                .with_help("a default must evaluate to a finite number"),
            );
            return None;
        }
        // The unit is the comment at the end of the value's line, if no other parameter
        // shares that line (`parameters: { m: 1, g: 9.81 }  # SI` names no unit).
        let line = v.location.line;
        let shared = per_line.get(&line).copied().unwrap_or(0) > 1;
        let unit = if unit_key.is_some() || shared {
            unit_key
        } else {
            let text = self.line(line);
            trailing_comment_of_line(text).map(|c| {
                let at = comment_location(text, line, &c);
                Located::new(c, at)
            })
        };
        Some(Parameter {
            name: k.clone(),
            default,
            value,
            unit,
        })
    }

    fn coordinates(&mut self, node: &YamlNode) -> Vec<Coordinate> {
        let items = match &node.kind {
            YamlKind::Seq(items) => items,
            other => {
                self.error(
                    Diagnostic::new(
                        node.location,
                        format!("`coordinates` must be a list of names, found {}", other.describe()),
                    )
                    .with_help("write `coordinates: [theta1, theta2]`, or one `- theta1  # comment` per line"),
                );
                return Vec::new();
            }
        };
        // How many coordinates start on each line, counted once (not per coordinate, which
        // was quadratic in a long one-line list).
        let mut per_line: HashMap<u32, usize> = HashMap::new();
        for item in items {
            *per_line.entry(item.location.line).or_default() += 1;
        }
        let mut out = Vec::new();
        for item in items {
            // The map form `{ name: x, unit: m }`.
            let mut unit = None;
            let named = if let YamlKind::Map(f) = &item.kind {
                const EXAMPLE: &str = "{ name: x, unit: m }";
                self.unknown_keys(f, "a coordinate", &["name", "unit"], &["name", "unit"]);
                if !self.require(f, item.location, "a coordinate", &["name"], EXAMPLE) {
                    continue;
                }
                if let Some(u) = get(f, "unit") {
                    unit = self.text(u, "the unit of a coordinate", "unit: m");
                }
                match get(f, "name") {
                    Some(n) => n,
                    None => continue,
                }
            } else {
                item
            };
            let Some(n) = self.name(named, "a coordinate") else {
                if let YamlKind::Scalar { text, .. } = &named.kind {
                    self.drop_name(text);
                }
                continue;
            };
            // A trailing comment describes the coordinate only if it is alone on its line.
            let alone = per_line[&item.location.line] == 1;
            let comment = if alone {
                trailing_comment_of_line(self.line(n.location.line))
            } else {
                None
            };
            out.push(Coordinate {
                name: n,
                comment,
                unit,
            });
        }
        // Rule: at most `MAX_COORDINATES` coordinates. The list is kept, so that the rest of
        // the file is checked against it (in time linear in its length) and this is the one
        // error of an otherwise sound file.
        if out.len() > MAX_COORDINATES {
            self.error(
                Diagnostic::new(
                    node.location,
                    format!(
                        "the model has {} generalized coordinates, more than the {MAX_COORDINATES} a model may have: its mass matrix is derived and evaluated as a dense {}×{} matrix",
                        out.len(),
                        out.len(),
                        out.len()
                    ),
                )
                .with_help(format!(
                    "use at most {MAX_COORDINATES} coordinates (a chain of {MAX_COORDINATES} masses loads, checks and takes its first step in seconds)"
                )),
            );
        }
        out
    }

    /// A map of names to expressions (`generalized_forces`, `initial`).
    fn keyed_exprs(
        &mut self,
        node: &YamlNode,
        what: &str,
        example: &str,
        item: &str,
    ) -> Vec<(Located<String>, Expr)> {
        let Some(entries) = self.map(node, what, example) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            if let Some(e) = self.expr(v, &format!("{item} (`{}`)", k.value)) {
                out.push((k.clone(), e));
            }
        }
        out
    }

    fn points(&mut self, node: &YamlNode) -> Vec<Point> {
        let Some(entries) = self.map(
            node,
            "`points`",
            "points: { O: [0, 0], P: [l*cos(q), l*sin(q)] }",
        ) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            if !self.key_name(k, "point") {
                continue;
            }
            match self.vector(
                v,
                &format!("point `{}`", k.value),
                "P: [l*cos(q), l*sin(q)]",
            ) {
                Some(position) => out.push(Point {
                    name: k.clone(),
                    position,
                    location: v.location,
                }),
                None => self.drop_name(&k.value),
            }
        }
        out
    }

    fn bodies(&mut self, node: &YamlNode) -> Vec<Body> {
        let Some(entries) = self.map(node, "`bodies`", "bodies: { bob: { mass: m, at: P } }")
        else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            if !self.key_name(k, "body") {
                continue;
            }
            match self.body(k, v) {
                Some(b) => out.push(b),
                None => self.drop_name(&k.value),
            }
        }
        out
    }

    fn body(&mut self, k: &Located<String>, v: &YamlNode) -> Option<Body> {
        let what = format!("body `{}`", k.value);
        let f = self.map(v, &what, &format!("{}: {PARTICLE_EXAMPLE}", k.value))?;
        self.unknown_keys(f, &what, BODY_KEYS, BODY_KEYS);
        let rigid_key = ["inertia", "com", "angle"]
            .into_iter()
            .find(|r| get(f, r).is_some());
        let Some(rigid_key) = rigid_key else {
            // A particle: `{ mass, at }`.
            let complete = self.require(
                f,
                k.location,
                &what,
                &["mass", "at"],
                &format!("{}: {PARTICLE_EXAMPLE}", k.value),
            );
            let mass = get(f, "mass").and_then(|n| self.expr(n, "a mass"));
            let at = get(f, "at").and_then(|n| self.name(n, "`at`"));
            let (Some(mass), Some(at), true) = (mass, at, complete) else {
                return None;
            };
            return Some(Body {
                name: k.clone(),
                kind: BodyKind::Particle { mass, at },
            });
        };
        // A planar rigid body: `{ mass, inertia, com, angle }`.
        if let Some(at) = get_key(f, "at") {
            self.error(
                Diagnostic::new(
                    at.location,
                    format!(
                        "{what} has `{rigid_key}`, so it is a planar rigid body, which has no `at`"
                    ),
                )
                .with_help(format!(
                    "a rigid body's position is its centre of mass `com`: `{RIGID_EXAMPLE}`; a particle is `{PARTICLE_EXAMPLE}`"
                )),
            );
        }
        let complete = self.require(
            f,
            k.location,
            &format!("{what} (a planar rigid body, as it has `{rigid_key}`)"),
            &["mass", "inertia", "com", "angle"],
            &format!("{}: {RIGID_EXAMPLE}", k.value),
        );
        let mass = get(f, "mass").and_then(|n| self.expr(n, "a mass"));
        let inertia = get(f, "inertia").and_then(|n| self.expr(n, "an inertia"));
        let com = get(f, "com").and_then(|n| self.name(n, "`com`"));
        let angle = get(f, "angle").and_then(|n| self.expr(n, "a body angle"));
        let (Some(mass), Some(inertia), Some(com), Some(angle), true) = (
            mass,
            inertia,
            com,
            angle,
            complete && get(f, "at").is_none(),
        ) else {
            return None;
        };
        Some(Body {
            name: k.clone(),
            kind: BodyKind::Rigid {
                mass,
                inertia,
                com,
                angle,
            },
        })
    }

    /// The fields of one named load (spring, damper, force, torque), or `None` if it is not
    /// a map or lacks a required field.
    fn fields<'n>(
        &mut self,
        k: &Located<String>,
        v: &'n YamlNode,
        kind: &str,
        allowed: &[&str],
        required: &[&str],
        example: &str,
    ) -> Option<&'n Entries> {
        let what = format!("{kind} `{}`", k.value);
        let example = format!("{}: {example}", k.value);
        let f = self.map(v, &what, &example)?;
        self.unknown_keys(f, &what, allowed, allowed);
        self.require(f, k.location, &what, required, &example)
            .then_some(f)
    }

    fn springs(&mut self, node: &YamlNode) -> Vec<Spring> {
        const EXAMPLE: &str = "{ between: [A, B], stiffness: k, rest_length: l0 }";
        let Some(entries) = self.map(node, "`springs`", &format!("springs: {{ s: {EXAMPLE} }}"))
        else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            let Some(f) = self.fields(
                k,
                v,
                "spring",
                &["between", "stiffness", "rest_length"],
                &["between", "stiffness"],
                EXAMPLE,
            ) else {
                continue;
            };
            let between = get(f, "between").and_then(|n| self.point_pair(n, "`between`"));
            let stiffness = get(f, "stiffness").and_then(|n| self.expr(n, "a stiffness"));
            let rest_length = match get(f, "rest_length") {
                Some(n) => self.expr(n, "a rest length").map(Some),
                None => Some(None),
            };
            if let (Some(between), Some(stiffness), Some(rest_length)) =
                (between, stiffness, rest_length)
            {
                out.push(Spring {
                    name: k.clone(),
                    between,
                    stiffness,
                    rest_length,
                });
            }
        }
        out
    }

    fn dampers(&mut self, node: &YamlNode) -> Vec<Damper> {
        const EXAMPLE: &str = "{ between: [A, B], coefficient: c }";
        let Some(entries) = self.map(node, "`dampers`", &format!("dampers: {{ d: {EXAMPLE} }}"))
        else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            let Some(f) = self.fields(
                k,
                v,
                "damper",
                &["between", "coefficient"],
                &["between", "coefficient"],
                EXAMPLE,
            ) else {
                continue;
            };
            let between = get(f, "between").and_then(|n| self.point_pair(n, "`between`"));
            let coefficient =
                get(f, "coefficient").and_then(|n| self.expr(n, "a damping coefficient"));
            if let (Some(between), Some(coefficient)) = (between, coefficient) {
                out.push(Damper {
                    name: k.clone(),
                    between,
                    coefficient,
                });
            }
        }
        out
    }

    fn forces(&mut self, node: &YamlNode) -> Vec<Force> {
        const EXAMPLE: &str = "{ at: P, vector: [F0*cos(w*t), 0] }";
        let Some(entries) = self.map(node, "`forces`", &format!("forces: {{ push: {EXAMPLE} }}"))
        else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            let Some(f) = self.fields(k, v, "force", &["at", "vector"], &["at", "vector"], EXAMPLE)
            else {
                continue;
            };
            let at = get(f, "at").and_then(|n| self.name(n, "`at`"));
            let vector = get(f, "vector").and_then(|n| {
                self.vector(
                    n,
                    &format!("the vector of force `{}`", k.value),
                    "vector: [Fx, Fy]",
                )
                .map(|x| (x, n.location))
            });
            if let (Some(at), Some((vector, location))) = (at, vector) {
                out.push(Force {
                    name: k.clone(),
                    at,
                    vector,
                    location,
                });
            }
        }
        out
    }

    fn torques(&mut self, node: &YamlNode) -> Vec<Torque> {
        const EXAMPLE: &str = "{ body: arm, value: tau0*sin(w*t) }";
        let Some(entries) = self.map(
            node,
            "`torques`",
            &format!("torques: {{ motor: {EXAMPLE} }}"),
        ) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            let Some(f) = self.fields(
                k,
                v,
                "torque",
                &["body", "value"],
                &["body", "value"],
                EXAMPLE,
            ) else {
                continue;
            };
            let body = get(f, "body").and_then(|n| self.name(n, "`body`"));
            let value = get(f, "value").and_then(|n| self.expr(n, "a torque"));
            if let (Some(body), Some(value)) = (body, value) {
                out.push(Torque {
                    name: k.clone(),
                    body,
                    value,
                });
            }
        }
        out
    }

    fn draw(&mut self, node: &YamlNode) -> Draw {
        let mut draw = Draw::default();
        let Some(f) = self.map(node, "`draw`", "draw: { lines: [[O, P]], trace: [P] }") else {
            return draw;
        };
        self.unknown_keys(f, "`draw`", &["lines", "trace"], &["lines", "trace"]);
        if let Some(lines) =
            get(f, "lines").and_then(|n| self.seq(n, "`lines`", "lines: [[O, E], [E, H]]"))
        {
            for l in lines {
                if let Some(pair) = self.point_pair(l, "a line") {
                    draw.lines.push(pair);
                }
            }
        }
        if let Some(trace) = get(f, "trace").and_then(|n| self.seq(n, "`trace`", "trace: [H]")) {
            for p in trace {
                if let Some(n) = self.name(p, "a traced point") {
                    draw.trace.push(n);
                }
            }
        }
        draw
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::yaml;

    fn built(src: &str) -> Built {
        let root = yaml::parse(src).unwrap();
        build_partial("t.yaml", src, &root)
    }

    fn messages(src: &str) -> Vec<String> {
        built(src)
            .diagnostics
            .iter()
            .map(|d| format!("{}: {}", d.location, d.message))
            .collect()
    }

    #[test]
    fn snake_case_names() {
        assert!(is_snake_case("double_pendulum2"));
        assert!(!is_snake_case("DoublePendulum"));
        assert_eq!(to_snake_case("DoublePendulum"), "double_pendulum");
        assert_eq!(to_snake_case("my-model"), "my_model");
        assert_eq!(to_snake_case("2d"), "model_2d");
        let m = messages("name: DoublePendulum\ncoordinates: [q]\n");
        assert_eq!(
            m,
            ["1:7: `name` must be snake_case, found `DoublePendulum`"]
        );
    }

    #[test]
    fn parameter_units_and_constant_defaults() {
        let src = "name: a\ncoordinates: [q]\nparameters:\n  m: 2.0  # kg\n  l: pi/4\n  k: 2*m\n";
        let b = built(src);
        let file = b.file.unwrap();
        assert_eq!(file.parameters.len(), 2);
        let unit = file.parameters[0].unit.as_ref().unwrap();
        assert_eq!(unit.value, "kg");
        assert_eq!(
            unit.location,
            Location {
                line: 4,
                column: 13
            }
        );
        assert_eq!(file.parameters[1].unit, None);
        assert!((file.parameters[1].value - std::f64::consts::FRAC_PI_4).abs() < 1e-15);
        assert_eq!(b.diagnostics.len(), 1);
        assert_eq!(b.diagnostics[0].location, Location { line: 6, column: 8 });
        assert!(
            b.diagnostics[0]
                .message
                .contains("parameter defaults must be constant")
        );
        assert_eq!(b.incomplete.names, ["k"]);
        // Several parameters on one line: no unit.
        let src = "name: a\ncoordinates: [q]\nparameters: { m: 1, g: 9.81 }  # SI\n";
        let file = built(src).file.unwrap();
        assert!(file.parameters.iter().all(|p| p.unit.is_none()));
    }

    #[test]
    fn coordinate_comments() {
        let src = "name: a\ncoordinates:\n  - x   # m, cart\n  - y\n";
        let file = built(src).file.unwrap();
        assert_eq!(file.coordinates[0].comment.as_deref(), Some("m, cart"));
        assert_eq!(file.coordinates[1].comment, None);
        let src = "name: a\ncoordinates: [x, y]  # both\n";
        let file = built(src).file.unwrap();
        assert!(file.coordinates.iter().all(|c| c.comment.is_none()));
    }

    #[test]
    fn later_keys_and_unknown_keys() {
        let m = messages("name: a\ncoordinates: [q]\noutputs: []\nkinetc: q_dot^2\n");
        assert_eq!(
            m,
            [
                "3:1: `outputs:` is not supported yet by this version of eomgen",
                "4:1: unknown key `kinetc` in a model file"
            ]
        );
        let b = built("name: a\ncoordinates: [q]\nkinetc: q_dot^2\n");
        assert!(
            b.diagnostics[0]
                .help
                .as_deref()
                .unwrap()
                .starts_with("did you mean `kinetic`?")
        );
    }

    #[test]
    fn reference_checks_with_their_defaults() {
        let src = "name: a\nparameters: { k: 1.0 }\ncoordinates: [q]\nkinetic: q_dot^2/2\npotential: k*q^2/2\nchecks:\n  natural_frequencies: { at: rest, values: [sqrt(k)] }\n  damping_ratios: { values: [0], tolerance: 1e-6 }\n  period: { event: peak, value: 2*pi, method: rk4, rtol: 1e-9, t_end: 20 }\n  final_state: { t: pi, values: { q: -1, q_dot: 0 } }\n  conserved: { p: q_dot, e: { value: q_dot^2 + k*q^2, tolerance: 1e-8 } }\n  energy_drift: {}\n  constraint_drift: { max: 1e-6 }\n";
        let built = built(src);
        assert!(built.diagnostics.is_empty(), "{:?}", built.diagnostics);
        let c = built.file.unwrap().checks;
        let w = c.natural_frequencies.unwrap();
        assert_eq!(w.at.unwrap().value, "rest");
        assert_eq!((w.values.len(), w.tolerance), (1, DEFAULT_CHECK_TOLERANCE));
        let z = c.damping_ratios.unwrap();
        assert!(z.at.is_none());
        assert_eq!(z.tolerance, 1e-6);
        let p = c.period.unwrap();
        assert_eq!(p.event.value, "peak");
        assert_eq!(p.run.method.unwrap().value, "rk4");
        assert_eq!((p.run.rtol, p.run.t_end), (Some(1e-9), Some(20.0)));
        let f = c.final_state.unwrap();
        let names: Vec<&str> = f.values.iter().map(|(k, _)| k.value.as_str()).collect();
        assert_eq!(names, ["q", "q_dot"]);
        assert_eq!(f.run, RunSettings::default());
        let tolerances: Vec<(&str, f64)> = c
            .conserved
            .iter()
            .map(|q| (q.name.value.as_str(), q.tolerance))
            .collect();
        assert_eq!(tolerances, [("p", DEFAULT_CHECK_TOLERANCE), ("e", 1e-8)]);
        assert_eq!(c.energy_drift.unwrap().max, DEFAULT_ENERGY_DRIFT);
        assert_eq!(c.constraint_drift.unwrap().max, 1e-6);
    }

    #[test]
    fn events_short_and_full_forms() {
        let src = "name: a\ncoordinates: [q]\nkinetic: q_dot^2/2\nevents:\n  cross: q\n  peak: { when: q_dot, direction: falling, terminal: true }\n";
        let file = built(src).file.unwrap();
        assert_eq!(file.events.len(), 2);
        assert_eq!(file.events[0].name.value, "cross");
        assert_eq!(
            (file.events[0].direction, file.events[0].terminal),
            (Crossing::Both, false)
        );
        assert_eq!(
            (file.events[1].direction, file.events[1].terminal),
            (Crossing::Falling, true)
        );
        let m = messages(
            "name: a\ncoordinates: [q]\nkinetic: q_dot^2/2\nevents:\n  peak: { when: q_dot, terminal: yes, directon: up }\n  bare: { direction: rising }\n",
        );
        assert_eq!(
            m,
            [
                "5:34: `terminal` of event `peak` must be one of true, false, found `yes`",
                "5:39: unknown key `directon` in event `peak`",
                "6:3: event `bare` has no `when`"
            ]
        );
    }

    /// `when: lhs = rhs` means `lhs − rhs = 0`, as `--stop-when "lhs = rhs"` does; a second
    /// `=` is an error at its column.
    #[test]
    fn an_event_may_be_written_as_an_equation() {
        let src = "name: a\ncoordinates: [y]\nkinetic: y_dot^2/2\nevents:\n  ground: { when: y = 0.5, terminal: true }\n  level: y_dot = -1\n";
        let file = built(src).file.unwrap();
        let at = |y: f64, y_dot: f64| {
            move |name: &str| match name {
                "y" => Some(y),
                "y_dot" => Some(y_dot),
                _ => None,
            }
        };
        let ground = &file.events[0].when;
        assert_eq!(eval_expr(ground, &at(2.0, 0.0)).unwrap(), 1.5);
        assert_eq!(eval_expr(ground, &at(0.5, 0.0)).unwrap(), 0.0);
        assert_eq!(eval_expr(&file.events[1].when, &at(0.0, 3.0)).unwrap(), 4.0);
        assert_eq!(
            ground.location,
            Location {
                line: 5,
                column: 19
            }
        );
        let m =
            messages("name: a\ncoordinates: [y]\nkinetic: y_dot^2/2\nevents:\n  e: y = 1 = 2\n");
        assert_eq!(
            m,
            ["5:12: the function of event `e` has one `=`, this is a second"]
        );
    }

    #[test]
    fn expressions_across_lines_keep_exact_locations() {
        let src = "name: a\ncoordinates: [q]\nkinetic: q_dot^2/2\n  + 3*\n";
        let m = messages(src);
        assert_eq!(
            m,
            ["4:7: expected an operand after `*`, found the end of the expression"]
        );
        let src = "name: a\ncoordinates: [q]\npotential: >\n  q^2/2\n  + )\n";
        let m = messages(src);
        assert_eq!(m, ["5:5: expected an operand after `+`, found `)`"]);
        let src = "name: a\ncoordinates: [q]\npotential: \"q^2 + $\"\n";
        assert_eq!(
            messages(src),
            ["3:19: unexpected character `$` in an expression"]
        );
    }

    #[test]
    fn a_comma_inside_a_flow_list_is_explained() {
        let src = "name: a\ncoordinates: [q]\npoints: { P: [atan2(q, 1), 0] }\n";
        let b = built(src);
        assert_eq!(b.diagnostics.len(), 1);
        assert!(
            b.diagnostics[0]
                .message
                .contains("`atan2(q` is cut at a `,`")
        );
        let src = "name: a\ncoordinates: [q]\npoints: { P: [\"atan2(q, 1)\", 0] }\n";
        assert!(built(src).diagnostics.is_empty());
    }

    #[test]
    fn a_comma_inside_a_flow_map_is_explained() {
        let src = "name: a\ncoordinates: [q]\npoints: { P: [q, 0] }\nbodies: { b: { mass: 1, inertia: 1, com: P, angle: atan2(q, 1) } }\n";
        let b = built(src);
        let d = b
            .diagnostics
            .iter()
            .find(|d| d.message.contains("unclosed"))
            .unwrap();
        assert!(
            d.help
                .as_deref()
                .unwrap()
                .contains("YAML splits values at every `,`")
        );
        // An unclosed parenthesis that YAML did not cut gets no such advice.
        let src = "name: a\ncoordinates: [q]\npotential: (q + 1\n";
        let b = built(src);
        assert_eq!(b.diagnostics.len(), 1);
        assert_eq!(
            b.diagnostics[0].help.as_deref(),
            Some("add the missing `)`")
        );
        let src = "name: a\ncoordinates: [q]\npoints: { P: [l*(q + 1, 0] }\n";
        let b = built(src);
        assert_eq!(b.diagnostics.len(), 1);
        assert!(b.diagnostics[0].message.contains("unclosed"));
    }

    #[test]
    fn bodies_particles_and_rigid() {
        let src = "name: a\ncoordinates: [q]\nbodies:\n  b: { inertia: 1, com: G, angle: q }\n  c: { mass: 1, at: P, angle: q }\n  d: { mas: 1, at: P }\n";
        let m = messages(src);
        assert_eq!(
            m,
            [
                "4:3: body `b` (a planar rigid body, as it has `inertia`) has no `mass`",
                "5:3: body `c` (a planar rigid body, as it has `angle`) has no `inertia`",
                "5:3: body `c` (a planar rigid body, as it has `angle`) has no `com`",
                "5:17: body `c` has `angle`, so it is a planar rigid body, which has no `at`",
                "6:8: unknown key `mas` in body `d`",
            ]
        );
        assert_eq!(built(src).incomplete.names, ["b", "c", "d"]);
    }
}
