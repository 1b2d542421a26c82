//! What a sweep file may not say, checked before any run is made: keys
//! of a sane shape, no law or seed fixed twice, nothing given twice, at most
//! [`MAX_RUNS`] runs, and every `[set]` and axis value valid for the
//! scenario (#31: each of these once aborted, overflowed or mislabelled).

use super::{MAX_RUNS, SweepFile, SweepFileError};
use crate::keys::{check_key_shape, set_key};
use crate::{Plan, Scenario};

/// Refuses what would make runs that are not what their labels say, or
/// identical runs counted as distinct: a law fixed beside `laws`, a seed
/// fixed beside `seeds`, a law or an axis given twice.
pub(super) fn check_distinct(spec: &SweepFile, file: &str) -> Result<(), SweepFileError> {
    let bad = |reason: String| SweepFileError::File {
        file: file.to_string(),
        reason,
    };
    let fixed = |key: &str| {
        spec.set.contains_key(key)
            || spec
                .set
                .get(key.split('.').next().unwrap_or(key))
                .and_then(|t| t.as_table())
                .is_some_and(|t| key.split('.').nth(1).is_some_and(|k| t.contains_key(k)))
            || spec.axis.iter().any(|a| a.key == key)
    };
    if !spec.laws.is_empty() && fixed("controller.law") {
        return Err(bad(
            "controller.law is set (in [set] or an axis) beside laws = [...]: give the laws in \
             one place"
                .into(),
        ));
    }
    if spec.seeds > 1 && fixed("seed") {
        return Err(bad(format!(
            "seed is set (in [set] or an axis) beside seeds = {}: every seed would run the \
             same; drop one of them",
            spec.seeds
        )));
    }
    for (i, law) in spec.laws.iter().enumerate() {
        if spec.laws[..i].contains(law) {
            return Err(bad(format!("laws lists {law} twice")));
        }
    }
    for (i, a) in spec.axis.iter().enumerate() {
        check_key_shape(&a.key).map_err(|e| bad(format!("axis: {e}")))?;
        if spec.axis[..i].iter().any(|b| b.key == a.key) {
            return Err(bad(format!("axis {} is given twice", a.key)));
        }
    }
    for key in spec.set.keys() {
        check_key_shape(key).map_err(|e| bad(format!("set: {e}")))?;
    }
    Ok(())
}

/// The number of runs, counted before anything is made.
pub(super) fn count_runs(
    spec: &SweepFile,
    laws: usize,
    file: &str,
) -> Result<usize, SweepFileError> {
    let mut total = laws
        .max(1)
        .saturating_mul(usize::try_from(spec.seeds).unwrap_or(usize::MAX));
    for a in &spec.axis {
        let n = a.count().ok_or_else(|| SweepFileError::File {
            file: file.to_string(),
            reason: format!("axis {}: give exactly one of values, range, random", a.key),
        })?;
        total = total.saturating_mul(n);
    }
    if total > MAX_RUNS {
        return Err(SweepFileError::File {
            file: file.to_string(),
            reason: format!(
                "{} runs: at most {MAX_RUNS} per sweep (each is resolved before the first starts; split a larger study into several sweeps)",
                if total == usize::MAX {
                    "too many".to_string()
                } else {
                    total.to_string()
                }
            ),
        });
    }
    Ok(total)
}

/// A key names a scenario key: setting it alone on the base scenario
/// parses (the error names the key, not a line of a generated file).
pub(super) fn check_key(
    base: &Plan,
    what: &str,
    key: &str,
    value: toml::Value,
    file: &str,
) -> Result<(), SweepFileError> {
    let bad = |reason: String| SweepFileError::File {
        file: file.to_string(),
        reason: format!("{what} {key}: {reason}"),
    };
    let mut tree = match toml::Value::try_from(&base.undrawn) {
        Ok(toml::Value::Table(t)) => t,
        _ => return Err(bad("cannot write the base scenario".into())),
    };
    set_key(&mut tree, key, value).map_err(|e| bad(e.to_string()))?;
    let text = toml::to_string(&tree).map_err(|e| bad(e.to_string()))?;
    match toml::from_str::<Scenario>(&text) {
        Ok(_) => Ok(()),
        // The parser's last line says what is wrong ("unknown field `k3`, …").
        Err(e) => {
            let msg = e.to_string();
            let last = msg.trim_end().lines().last().unwrap_or("").to_string();
            Err(bad(last))
        }
    }
}
