//! Dotted scenario keys (`plant.payload.mass`): their shape, `--set`'s
//! `KEY=VALUE`, and setting one in a scenario's TOML tree. `--set`, a
//! sweep file's axes and its `[set]` table all go through here.

/// Why a dotted key or a `KEY=VALUE` is refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum KeyError {
    /// More than [`MAX_KEY_PARTS`] parts (the key shown cut to 40 characters).
    #[error("'{0}…' has more than {MAX_KEY_PARTS} dotted parts; scenario keys have at most 3")]
    TooDeep(String),
    /// An empty part.
    #[error("'{0}' is not a dotted scenario key")]
    NotDotted(String),
    /// A part that names a value where a table is needed.
    #[error("'{0}' is a value, not a table")]
    NotATable(String),
    /// No `=`.
    #[error("{0:?} is not KEY=VALUE (e.g. controller.k1=20)")]
    NotKeyValue(String),
}

/// Parts a dotted scenario key may have: the deepest scenario key has 3
/// (`plant.payload.mass`); a longer one is refused before it is built.
pub const MAX_KEY_PARTS: usize = 8;

/// A dotted scenario key of at most [`MAX_KEY_PARTS`] non-empty parts.
pub(crate) fn check_key_shape(key: &str) -> Result<(), KeyError> {
    let parts = key.split('.').take(MAX_KEY_PARTS + 1).collect::<Vec<_>>();
    if parts.len() > MAX_KEY_PARTS {
        return Err(KeyError::TooDeep(key.chars().take(40).collect()));
    }
    if parts.iter().any(|p| p.is_empty()) {
        return Err(KeyError::NotDotted(key.to_string()));
    }
    Ok(())
}

/// Sets the dotted `key` in a scenario's TOML tree, creating tables.
pub(crate) fn set_key(
    root: &mut toml::Table,
    key: &str,
    value: toml::Value,
) -> Result<(), KeyError> {
    check_key_shape(key)?;
    let parts: Vec<&str> = key.split('.').collect();
    let mut table = root;
    for (i, part) in parts.iter().enumerate() {
        if i + 1 == parts.len() {
            table.insert((*part).to_string(), value);
            return Ok(());
        }
        let entry = table
            .entry((*part).to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        table = match entry {
            toml::Value::Table(t) => t,
            _ => {
                return Err(KeyError::NotATable(parts[..=i].join(".")));
            }
        };
    }
    Ok(())
}

/// Reads `key.path=value` (the value in TOML; a bare word is a string).
pub fn parse_set(arg: &str) -> Result<(String, toml::Value), KeyError> {
    let Some((key, raw)) = arg.split_once('=') else {
        return Err(KeyError::NotKeyValue(arg.to_string()));
    };
    let key = key.trim().to_string();
    check_key_shape(&key)?;
    let raw = raw.trim();
    let value = toml::from_str::<toml::Table>(&format!("v = {raw}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(raw.to_string()));
    Ok((key, value))
}
