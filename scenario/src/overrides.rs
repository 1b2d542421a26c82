//! The command line's overrides of a scenario (`--duration`, `--rate`,
//! `--robot`, `--law`, `--set key=value`): applied to the scenario's TOML
//! text before it is read, so that they are checked as the file is, and
//! a refused `--set` is named with its value.

use std::path::PathBuf;

use plant_rapier::Locks;

use crate::{Scenario, ScenarioError};

/// Command-line values that replace the scenario's own.
#[derive(Debug, Clone, Default)]
pub struct Overrides {
    /// Replaces `duration_s`.
    pub duration_s: Option<f64>,
    /// Replaces `rate_hz`.
    pub rate_hz: Option<f64>,
    /// Replaces the robot; with no scenario file, the default scenario for
    /// that arm is used.
    pub robot: Option<PathBuf>,
    /// Runs this law on the scenario: its shared keys (T_c, K1, K2) are
    /// kept, keys the law does not take go back to their defaults
    /// ([`controller::ControllerParams::for_law`]), as in `compare`.
    pub law: Option<controller::LawName>,
    /// `--set key.path=value`, applied in order to the scenario's TOML
    /// before it is read (so checked like the file).
    pub set: Vec<(String, toml::Value)>,
}

/// `text` with every `set` applied; `source` says so, for messages.
pub(crate) fn apply_set(
    text: &str,
    source: &str,
    set: &[(String, toml::Value)],
) -> Result<(String, String), ScenarioError> {
    let err = |message: String| ScenarioError::Toml {
        file: source.to_string(),
        message,
    };
    let mut root: toml::Table = toml::from_str(text).map_err(|e| err(e.to_string()))?;
    let mut said = Vec::new();
    for (key, value) in set {
        crate::keys::set_key(&mut root, key, value.clone())
            .map_err(|e| err(format!("--set {}: {}", cut(key), cut_lines(&e.to_string()))))?;
        said.push(format!("--set {}={}", cut(key), cut(&value.to_string())));
    }
    let text = toml::to_string(&root).map_err(|e| err(e.to_string()))?;
    Ok((text, format!("{source} with {}", said.join(" "))))
}

/// Which `--set` makes `text` no scenario, and why, in its own terms:
/// the merged document's line numbers mean nothing to whoever typed it.
/// The set without which the rest reads (a later set may replace an
/// earlier bad one); else the first that breaks what came before. None
/// when the sets are not what fails (the caller's message stands).
pub(crate) fn blame_set(text: &str, set: &[(String, toml::Value)]) -> Option<String> {
    let root: toml::Table = toml::from_str(text).ok()?;
    toml::from_str::<Scenario>(text).ok()?;
    let reads = |sets: &mut dyn Iterator<Item = &(String, toml::Value)>| {
        let mut merged = root.clone();
        for (key, value) in sets {
            crate::keys::set_key(&mut merged, key, value.clone()).ok()?;
        }
        let merged = toml::to_string(&merged).ok()?;
        Some(toml::from_str::<Scenario>(&merged).map(|_| ()))
    };
    let culprit = (0..set.len())
        .rev()
        .find(|&i| {
            let mut others = set
                .iter()
                .enumerate()
                .filter(|(k, _)| *k != i)
                .map(|(_, s)| s);
            matches!(reads(&mut others), Some(Ok(())))
        })
        .or_else(|| {
            (1..=set.len())
                .find(|&n| matches!(reads(&mut set[..n].iter()), Some(Err(_))))
                .map(|n| n - 1)
        })?;
    let (key, value) = &set[culprit];
    let Some(Err(e)) = reads(&mut set[..=culprit].iter()) else {
        return None;
    };
    let message = e.message().trim_end();
    Some(format!(
        "--set {}={}: {}{}",
        cut(key),
        cut(&value.to_string()),
        cut_lines(message),
        as_string_hint(value, message)
    ))
}

/// The most characters of a typed value a message quotes: a `--set` of
/// 2 million entries made a 10 MB message and 650 MB of memory (#48 item 9).
const QUOTED: usize = 80;

/// `v` cut to [`QUOTED`] characters, with its length when cut.
fn cut(v: &str) -> String {
    match v.char_indices().nth(QUOTED) {
        None => v.to_string(),
        Some((at, _)) => format!("{}… ({} bytes in all)", &v[..at], v.len()),
    }
}

/// Each line of a reader's message cut as [`cut`] does (TOML's messages
/// quote the offending line whole), and at most 8 lines.
fn cut_lines(message: &str) -> String {
    message
        .lines()
        .take(8)
        .map(cut)
        .collect::<Vec<_>>()
        .join("\n")
}

/// Why a `--set` value the scenario refuses may not be what was typed:
/// a value that is not TOML is read as a string.
fn as_string_hint(value: &toml::Value, message: &str) -> String {
    let toml::Value::String(raw) = value else {
        return String::new();
    };
    // A bare word where a word is wanted (an unknown engine) is fine.
    if message.contains("unknown variant")
        || toml::from_str::<toml::Table>(&format!("v = {raw}")).is_ok()
    {
        return String::new();
    }
    if raw.parse::<f64>().is_ok() {
        format!(
            " ('{}' is out of TOML's range for a number, so it was read as a string)",
            cut(raw)
        )
    } else {
        format!(
            " ('{}' is not a TOML value, so it was read as a string)",
            cut(raw)
        )
    }
}

/// The joints `--set plant.lock.J=POSITION` locks: the default scenario
/// of an arm is chosen with them locked (a 34-joint hand runs once two are).
pub(crate) fn set_locks(set: &[(String, toml::Value)]) -> Locks {
    set.iter()
        .filter_map(|(key, value)| {
            let joint = key.strip_prefix("plant.lock.")?;
            let position = match value {
                toml::Value::Float(x) => *x,
                toml::Value::Integer(i) => *i as f64,
                _ => return None,
            };
            Some((joint.to_string(), position))
        })
        .collect()
}

/// `text` with its `[controller]` table replaced by `params`.
pub(crate) fn with_controller(
    text: &str,
    source: &str,
    params: &controller::ControllerParams,
) -> Result<String, ScenarioError> {
    let err = |message: String| ScenarioError::Toml {
        file: source.to_string(),
        message,
    };
    let mut root: toml::Table = toml::from_str(text).map_err(|e| err(e.to_string()))?;
    let table = toml::Value::try_from(params).map_err(|e| err(e.to_string()))?;
    root.insert("controller".into(), table);
    toml::to_string(&root).map_err(|e| err(e.to_string()))
}
