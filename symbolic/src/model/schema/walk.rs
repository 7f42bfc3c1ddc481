//! The scaffold that every keyed part of a model file shares, written once: a map whose keys
//! are checked against a list, a map of named entries walked entry by entry ([`Keyed`]), and
//! the keys of one entry with the ones it needs ([`Fields`]).
//!
//! A section's reader then only says how each of its values is read; what is reported for
//! a wrong shape, an unknown key or a missing one, and where, is decided here.

use super::entries::listed;
use super::*;

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

/// The state of the pass: the source, what was found wrong, and what was left out.
pub(crate) struct Ctx<'s> {
    pub(super) source: &'s str,
    /// The lines of `source`, looked up by number (1-based) with [`Ctx::line`].
    pub(super) lines: Vec<&'s str>,
    pub(super) diagnostics: Diagnostics,
    pub(super) incomplete: Incomplete,
    /// The top-level key being read; every error marks it incomplete.
    pub(super) section: &'static str,
}

impl<'s> Ctx<'s> {
    /// The pass over `source`, with nothing found yet.
    pub(super) fn new(source: &'s str) -> Self {
        Self {
            source,
            lines: source.lines().collect(),
            diagnostics: Diagnostics::new(),
            incomplete: Incomplete::default(),
            section: "",
        }
    }

    /// The text of line `line` (1-based) of the source, empty past its end.
    pub(super) fn line(&self, line: u32) -> &'s str {
        line.checked_sub(1)
            .and_then(|i| self.lines.get(i as usize))
            .copied()
            .unwrap_or_default()
    }

    pub(crate) fn error(&mut self, d: Diagnostic) {
        self.diagnostics.push(d);
        if !self.section.is_empty() && !self.incomplete.has_section(self.section) {
            self.incomplete.sections.push(self.section.to_string());
        }
    }

    pub(super) fn drop_name(&mut self, name: &str) {
        if !self.incomplete.has_name(name) {
            self.incomplete.names.push(name.to_string());
        }
    }
}

/// Whether an entry must have a key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Need {
    /// Reported when missing.
    Required,
    /// May be left out.
    Optional,
}

/// The keys of one kind of entry (a spring, a check, …): every key it takes, in the order
/// messages list them, and whether it needs it.
pub(crate) struct Fields {
    /// What the entry is, for messages: `"spring"`.
    pub(crate) kind: &'static str,
    /// Its keys.
    pub(crate) keys: &'static [(&'static str, Need)],
    /// How to write one, after `name: ` (`{ between: [A, B], stiffness: k }`).
    pub(crate) example: &'static str,
}

/// A map of named entries (`springs: { s1: {…}, s2: {…} }`): how [`Ctx::keyed`] walks it.
pub(crate) struct Keyed<'a> {
    /// The map as messages name it (`` `springs` ``).
    pub(crate) what: &'a str,
    /// The map written out, for the message when it is not a map.
    pub(crate) example: &'a str,
    /// What an entry is called when its key must be a name (`"point"`); `None` when any key
    /// is taken as it is.
    pub(crate) names: Option<&'a str>,
    /// Whether an entry that cannot be read is recorded as left out ([`Incomplete::names`]).
    pub(crate) drop: bool,
}

impl Ctx<'_> {
    /// Walks the map of named entries `node`: reports a value that is not a map and keys that
    /// are not names (when `spec` asks for names), and reads each entry with `read`, in file
    /// order; the entries read.
    pub(crate) fn keyed<T>(
        &mut self,
        node: &YamlNode,
        spec: Keyed<'_>,
        mut read: impl FnMut(&mut Self, &Located<String>, &YamlNode) -> Option<T>,
    ) -> Vec<T> {
        let Some(entries) = self.map(node, spec.what, spec.example) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (k, v) in entries {
            if let Some(names) = spec.names
                && !self.key_name(k, names)
            {
                continue;
            }
            match read(self, k, v) {
                Some(entry) => out.push(entry),
                None if spec.drop => self.drop_name(&k.value),
                None => {}
            }
        }
        out
    }

    /// The fields of the entry `k: v` of kind `spec`, or `None` if it is not a map or lacks a
    /// key it needs; reports the keys it does not take.
    pub(crate) fn fields<'n>(
        &mut self,
        k: &Located<String>,
        v: &'n YamlNode,
        spec: &Fields,
    ) -> Option<&'n Entries> {
        let allowed: Vec<&str> = spec.keys.iter().map(|(key, _)| *key).collect();
        let required: Vec<&str> = spec
            .keys
            .iter()
            .filter(|(_, need)| *need == Need::Required)
            .map(|(key, _)| *key)
            .collect();
        let what = format!("{} `{}`", spec.kind, k.value);
        let example = format!("{}: {}", k.value, spec.example);
        let f = self.map(v, &what, &example)?;
        self.unknown_keys(f, &what, &allowed, &allowed);
        self.require(f, k.location, &what, &required, &example)
            .then_some(f)
    }

    /// Reports every key of `entries` that is not in `allowed`.
    pub(crate) fn unknown_keys(
        &mut self,
        entries: &Entries,
        what: &str,
        allowed: &[&str],
        listed: &[&str],
    ) {
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
    pub(crate) fn require(
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

    /// The entries of the map `node` (none for an empty value); reports anything else.
    pub(crate) fn map<'n>(
        &mut self,
        node: &'n YamlNode,
        what: &str,
        example: &str,
    ) -> Option<&'n Entries> {
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
}
