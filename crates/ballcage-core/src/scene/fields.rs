//! The unit and meaning of every field of a scene document: one table per
//! spec struct, kept beside the struct ([`FieldDoc`] lists such as
//! `BodySpec::FIELDS`), and the walk that answers for a dotted key.
//!
//! A unit is written as `scene show` prints it: `m`, `kg·m²`, `N·m/rad`;
//! `-` for a pure number, empty for text, booleans and tables. Scene fields
//! are SI except those whose name says `_deg` or `_rpm`. A contact law's
//! fields are in the law's own `units`, so their unit is a rule of the law
//! ([`Fields::Law`]), not a fixed string.

use super::overrides::{key_parts, lookup};
use crate::error::SceneError;

/// The unit and meaning of one field, as [`describe`] answers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldInfo {
    /// Unit as printed (`m`, `N/mm^2.2`); `-` for a pure number, empty for
    /// text, booleans and tables.
    pub unit: String,
    /// One line on what the field is.
    pub meaning: &'static str,
}

/// The unit and meaning of a field of a contact law table (`law = …`),
/// which depend on the law and its `units`; `None` for a key the law does
/// not document.
pub type LawRule = fn(key: &str, law: &toml::Table) -> Option<FieldInfo>;

/// What a field holds.
#[derive(Debug, Clone, Copy)]
pub enum Fields {
    /// A number, an array of numbers, text or a boolean.
    Leaf,
    /// A number that may be left out, its absence meaning something (the
    /// meaning says what): `scene show` lists it as a comment when unset.
    Optional,
    /// A table with these fields.
    Table(&'static [FieldDoc]),
    /// An array of tables, each with these fields.
    Tables(&'static [FieldDoc]),
    /// A contact law, whose fields the rule describes.
    Law(LawRule),
}

/// One field of a scene document: its key in its table, unit and meaning.
#[derive(Debug, Clone, Copy)]
pub struct FieldDoc {
    /// Key within its table (`curvature_radius`).
    pub key: &'static str,
    /// Unit as printed; `-` for a pure number, empty for text and tables.
    pub unit: &'static str,
    /// One line on what the field is.
    pub meaning: &'static str,
    /// What the field holds.
    pub fields: Fields,
}

impl FieldDoc {
    /// A number or an array of numbers, in `unit` (`-`: a pure number).
    pub const fn number(key: &'static str, unit: &'static str, meaning: &'static str) -> Self {
        Self {
            key,
            unit,
            meaning,
            fields: Fields::Leaf,
        }
    }

    /// Text, a boolean or a list of names: no unit.
    pub const fn text(key: &'static str, meaning: &'static str) -> Self {
        Self {
            key,
            unit: "",
            meaning,
            fields: Fields::Leaf,
        }
    }

    /// A number in `unit` that may be left out; `meaning` says what its
    /// absence means.
    pub const fn optional(key: &'static str, unit: &'static str, meaning: &'static str) -> Self {
        Self {
            key,
            unit,
            meaning,
            fields: Fields::Optional,
        }
    }

    /// A table with `fields`.
    pub const fn table(
        key: &'static str,
        meaning: &'static str,
        fields: &'static [FieldDoc],
    ) -> Self {
        Self {
            key,
            unit: "",
            meaning,
            fields: Fields::Table(fields),
        }
    }

    /// An array of tables, each with `fields`.
    pub const fn tables(
        key: &'static str,
        meaning: &'static str,
        fields: &'static [FieldDoc],
    ) -> Self {
        Self {
            key,
            unit: "",
            meaning,
            fields: Fields::Tables(fields),
        }
    }

    /// A contact law table, its fields described by `rule`.
    pub const fn law(key: &'static str, meaning: &'static str, rule: LawRule) -> Self {
        Self {
            key,
            unit: "",
            meaning,
            fields: Fields::Law(rule),
        }
    }

    fn info(&self) -> FieldInfo {
        FieldInfo {
            unit: self.unit.to_string(),
            meaning: self.meaning,
        }
    }
}

/// Every key of `docs` as a dotted path, arrays of tables as `bodies[]`
/// and a law's fields left out (they depend on the law): for listings and
/// for the tests that keep the tables complete.
pub fn flatten(docs: &'static [FieldDoc]) -> Vec<(String, &'static FieldDoc)> {
    let mut out = Vec::new();
    for doc in docs {
        out.push((doc.key.to_string(), doc));
        let (inner, sep) = match doc.fields {
            Fields::Table(inner) => (inner, "."),
            Fields::Tables(inner) => (inner, "[]."),
            Fields::Leaf | Fields::Optional | Fields::Law(_) => continue,
        };
        for (key, d) in flatten(inner) {
            out.push((format!("{}{sep}{key}", doc.key), d));
        }
    }
    out
}

/// The unit and meaning of the field at the dotted `key` (`pipe.pitch`,
/// `bodies[1].mass` or `bodies.1.mass`; an element of an array of numbers,
/// `pipe.link_inertia[0]`, answers as its array) of the document `root`,
/// whose fields `docs` lists. An error names the key: one the document does
/// not have, or (a bug) a field no table documents.
pub fn describe(
    docs: &'static [FieldDoc],
    root: &toml::Value,
    key: &str,
) -> Result<FieldInfo, SceneError> {
    if key.trim().is_empty() {
        return Err(SceneError::new(
            "",
            "",
            "give a dotted key, e.g. pipe.pitch",
        ));
    }
    lookup(root, key)?;
    let parts = key_parts(key);
    let (mut value, mut holds) = (root, Fields::Table(docs));
    let mut info: Option<FieldInfo> = None;
    for (i, part) in parts.iter().enumerate() {
        let undocumented = || {
            SceneError::new(
                parts[..=i].join("."),
                "",
                "has no documented unit (a field missing from its spec's FIELDS table: a bug)",
            )
        };
        match value {
            toml::Value::Array(items) => {
                // An element: of an array of tables, or of numbers (its array's unit).
                value = part
                    .parse::<usize>()
                    .ok()
                    .and_then(|k| items.get(k))
                    .ok_or_else(undocumented)?;
                if let Fields::Tables(inner) = holds {
                    holds = Fields::Table(inner);
                }
            }
            toml::Value::Table(table) => {
                value = table.get(part.as_str()).ok_or_else(undocumented)?;
                (info, holds) = match holds {
                    Fields::Table(list) => {
                        let doc = list
                            .iter()
                            .find(|d| d.key == part)
                            .ok_or_else(undocumented)?;
                        (Some(doc.info()), doc.fields)
                    }
                    Fields::Law(rule) => (
                        Some(rule(part, table).ok_or_else(undocumented)?),
                        Fields::Leaf,
                    ),
                    Fields::Leaf | Fields::Optional | Fields::Tables(_) => {
                        return Err(undocumented());
                    }
                };
            }
            _ => return Err(undocumented()),
        }
    }
    info.ok_or_else(|| SceneError::new(key, "", "is not a field"))
}

/// `text`, a document as `to_toml` writes it (table headers and
/// `key = value` lines at the start of a line, arrays over several lines),
/// with `  # unit` after each line that sets a number or an array of
/// numbers, and a comment line `# key: unset, meaning [unit]` at the end of
/// each table for each of its optional fields (`Fields::Optional`) the
/// document leaves out; `root` is the parsed document and `docs` its
/// fields. A line that sets a number is preceded by the comment line
/// `# <mark>` when `mark(dotted key, unit)` gives one (a PROPOSAL's range
/// and source, [`super::Proposal::mark`]). The text parses to the same values.
pub fn annotate(
    text: &str,
    docs: &'static [FieldDoc],
    root: &toml::Value,
    mark: &dyn Fn(&str, &str) -> Option<String>,
) -> String {
    let mut section = String::new();
    // Elements seen so far of each array of tables (`[[bodies]]`), by its dotted name.
    let mut seen: std::collections::HashMap<String, usize> = Default::default();
    let mut out = String::with_capacity(text.len() + text.len() / 4);
    for line in text.lines() {
        if line.starts_with('[') {
            unset_fields(&mut out, docs, root, &section);
        }
        if let Some(header) = line.strip_prefix('[') {
            out.push_str(line);
            let name = header.trim_matches(|c| c == '[' || c == ']');
            if header.starts_with('[') {
                *seen.entry(name.to_string()).or_default() += 1;
            }
            section = indexed(root, name, &seen).unwrap_or_default();
        } else if let Some((key, _)) = line.split_once(" = ")
            && !line.starts_with(' ')
        {
            let full = if section.is_empty() {
                key.to_string()
            } else {
                format!("{section}.{key}")
            };
            let unit = lookup(root, &full)
                .ok()
                .filter(|v| is_numeric(v))
                .and_then(|_| describe(docs, root, &full).ok())
                .map(|info| info.unit)
                .filter(|u| !u.is_empty());
            if let Some(comment) = unit.as_deref().and_then(|u| mark(&full, u)) {
                out.push_str("# ");
                out.push_str(&comment);
                out.push('\n');
            }
            out.push_str(line);
            if let Some(unit) = unit {
                out.push_str("  # ");
                out.push_str(&unit);
            }
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    unset_fields(&mut out, docs, root, &section);
    out
}

/// Appends `# key: unset, meaning [unit]` for each optional field of the
/// table at dotted `section` (indices of arrays of tables included) that
/// `root` leaves out.
fn unset_fields(out: &mut String, docs: &'static [FieldDoc], root: &toml::Value, section: &str) {
    let mut list = docs;
    for part in section
        .split('.')
        .filter(|p| !p.is_empty() && p.parse::<usize>().is_err())
    {
        match list.iter().find(|d| d.key == part).map(|d| d.fields) {
            Some(Fields::Table(inner) | Fields::Tables(inner)) => list = inner,
            _ => return,
        }
    }
    // Inside the table: before the blank line that ends it, if any.
    let blank = out.ends_with("\n\n");
    if blank {
        out.pop();
    }
    for doc in list.iter().filter(|d| matches!(d.fields, Fields::Optional)) {
        let key = if section.is_empty() {
            doc.key.to_string()
        } else {
            format!("{section}.{}", doc.key)
        };
        if lookup(root, &key).is_err() {
            out.push_str(&format!(
                "# {}: unset, {} [{}]\n",
                doc.key, doc.meaning, doc.unit
            ));
        }
    }
    if blank {
        out.push('\n');
    }
}

/// The dotted header `name` of `root` with the index of the last element
/// `seen` so far of each array of tables on the way (`contacts.3.normal`).
fn indexed(
    root: &toml::Value,
    name: &str,
    seen: &std::collections::HashMap<String, usize>,
) -> Option<String> {
    let (mut v, mut prefix, mut path) = (root, String::new(), Vec::new());
    for seg in name.split('.').filter(|s| !s.is_empty()) {
        if !prefix.is_empty() {
            prefix.push('.');
        }
        prefix.push_str(seg);
        v = v.get(seg)?;
        path.push(seg.to_string());
        if let toml::Value::Array(items) = v {
            let k = seen.get(&prefix)?.checked_sub(1)?;
            v = items.get(k)?;
            path.push(k.to_string());
        }
    }
    Some(path.join("."))
}

/// A number, or a non-empty array of numbers.
pub(crate) fn is_numeric(v: &toml::Value) -> bool {
    match v {
        toml::Value::Integer(_) | toml::Value::Float(_) => true,
        toml::Value::Array(a) => !a.is_empty() && a.iter().all(is_numeric),
        _ => false,
    }
}

/// Every numeric leaf of `v` under `path` (dotted, array elements by
/// index; an array of numbers counts as one leaf), for the tests that
/// every number a document prints has a unit.
pub fn numeric_keys(v: &toml::Value, path: &str) -> Vec<String> {
    let join = |k: &str| {
        if path.is_empty() {
            k.to_string()
        } else {
            format!("{path}.{k}")
        }
    };
    match v {
        _ if is_numeric(v) => vec![path.to_string()],
        toml::Value::Table(t) => t
            .iter()
            .flat_map(|(k, x)| numeric_keys(x, &join(k)))
            .collect(),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .flat_map(|(i, x)| numeric_keys(x, &join(&i.to_string())))
            .collect(),
        _ => vec![],
    }
}
