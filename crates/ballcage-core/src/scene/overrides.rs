//! `dotted.key=value` overrides applied to a scene table before validation.

use crate::error::SceneError;

/// The parts of a dotted key; a list element may be written `bodies.1.mass`
/// or, as error messages print paths, `bodies[1].mass`.
pub(crate) fn key_parts(key: &str) -> Vec<String> {
    key.trim()
        .replace('[', ".")
        .replace(']', "")
        .split('.')
        .map(str::to_string)
        .collect()
}

/// Sets `key` (dotted; array elements by index, `bodies.1.mass` or `bodies[1].mass`) to `value`
/// parsed as a TOML value (`3`, `1e-4`, `"rk4"`, `[0, 0, -9.8]`); a value that
/// does not parse as TOML is taken as a string.
pub fn apply_override(root: &mut toml::Value, assignment: &str) -> Result<(), SceneError> {
    let Some((key, raw)) = assignment.split_once('=') else {
        return Err(SceneError::new(
            assignment,
            "",
            "an override is written key=value",
        ));
    };
    let key = key.trim();
    let raw = raw.trim();
    if key.is_empty() {
        return Err(SceneError::new(
            assignment,
            "",
            "an override needs a key before `=`",
        ));
    }
    let value = parse_value(raw);
    let parts = key_parts(key);
    let mut cur: &mut toml::Value = root;
    for (i, part) in parts.iter().enumerate() {
        let last = i + 1 == parts.len();
        let here = parts[..=i].join(".");
        cur = match cur {
            toml::Value::Table(t) => {
                if last {
                    t.insert(part.clone(), value);
                    return Ok(());
                }
                t.entry(part.clone())
                    .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            }
            toml::Value::Array(a) => {
                let idx: usize = part.parse().map_err(|_| {
                    SceneError::new(&here, part, "this level is a list: index it with a number")
                })?;
                let len = a.len();
                let Some(slot) = a.get_mut(idx) else {
                    return Err(SceneError::new(
                        &here,
                        idx,
                        format!("index out of range (the list has {len} items)"),
                    ));
                };
                if last {
                    *slot = value;
                    return Ok(());
                }
                slot
            }
            _ => {
                return Err(SceneError::new(
                    &here,
                    "",
                    "is not a table or list, so it has no sub-keys",
                ));
            }
        };
    }
    Ok(())
}

fn parse_value(raw: &str) -> toml::Value {
    let doc = format!("v = {raw}");
    match doc.parse::<toml::Table>() {
        Ok(mut t) => t
            .remove("v")
            .unwrap_or_else(|| toml::Value::String(raw.to_string())),
        Err(_) => toml::Value::String(raw.to_string()),
    }
}

/// The value at dotted `key` (the syntax of [`apply_override`]) in `root`.
pub fn lookup<'a>(root: &'a toml::Value, key: &str) -> Result<&'a toml::Value, SceneError> {
    let mut cur = root;
    let parts = key_parts(key);
    for (i, part) in parts.iter().enumerate() {
        let here = parts[..=i].join(".");
        cur = match cur {
            toml::Value::Table(t) => t.get(part.as_str()).ok_or_else(|| {
                let keys: Vec<&str> = t.keys().map(String::as_str).collect();
                SceneError::new(
                    &here,
                    "",
                    format!("no such key (keys here: {})", keys.join(", ")),
                )
            })?,
            toml::Value::Array(a) => {
                let idx: usize = part.parse().map_err(|_| {
                    SceneError::new(&here, part, "this level is a list: index it with a number")
                })?;
                a.get(idx).ok_or_else(|| {
                    SceneError::new(
                        &here,
                        idx,
                        format!("index out of range (the list has {} items)", a.len()),
                    )
                })?
            }
            _ => {
                return Err(SceneError::new(
                    &here,
                    "",
                    "is not a table or list, so it has no sub-keys",
                ));
            }
        };
    }
    Ok(cur)
}
