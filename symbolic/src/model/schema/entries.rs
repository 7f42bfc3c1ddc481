//! Lookups in the entries of a YAML map, shared by the walker and the section readers (a leaf:
//! it takes nothing from the schema's other files).

use super::super::located::Located;
use super::super::parser::closest;
use super::super::yaml::YamlNode;

/// The entries of a YAML map, in file order.
pub(crate) type Entries = [(Located<String>, YamlNode)];

/// The value of `key` in `entries`.
pub(crate) fn get<'n>(entries: &'n Entries, key: &str) -> Option<&'n YamlNode> {
    entries.iter().find(|(k, _)| k.value == key).map(|(_, v)| v)
}

/// Whether `entries` has a key that is a misspelling of the missing key `key`: it is then
/// reported once, as an unknown key with "did you mean `key`?", not also as missing.
pub(super) fn misspelt(entries: &Entries, key: &str) -> bool {
    entries
        .iter()
        .any(|(k, _)| k.value != key && closest(&k.value, &[key]).is_some())
}

/// The key `key` itself, for its location.
pub(crate) fn get_key<'n>(entries: &'n Entries, key: &str) -> Option<&'n Located<String>> {
    entries.iter().find(|(k, _)| k.value == key).map(|(k, _)| k)
}

/// The keys present, for messages: `` `inertia`, `com` ``.
pub(super) fn listed(entries: &Entries) -> String {
    if entries.is_empty() {
        return "nothing".to_string();
    }
    entries
        .iter()
        .map(|(k, _)| format!("`{}`", k.value))
        .collect::<Vec<_>>()
        .join(", ")
}
