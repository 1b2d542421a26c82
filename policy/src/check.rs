//! Whether a run is the one a policy was trained for: its period, T_c,
//! K1, K2 and joint count must be the training scenario's (they shape the
//! base law's torque the policy learnt a residual on, and the error it
//! saw); other `[controller]` settings that differ are warned about. The
//! same rules as python `testbed.policy_node` (issue 48, N8).

use serde_json::Value;

use controller::ControllerParams;
use controller::node::ControllerNodeConfig;

use crate::{EnvRecord, PolicyError};

/// The `[controller]` settings a run is refused on when they differ.
pub const ESSENTIAL: [&str; 3] = ["tc", "k1", "k2"];

/// Refuses a run whose dof, period, tc, k1 or k2 differ from the record's
/// (naming the field and both values); returns warnings about the rest.
pub fn check_run(
    record: &EnvRecord,
    config: &ControllerNodeConfig,
) -> Result<Vec<String>, PolicyError> {
    let mut notes = Vec::new();
    if config.dof != record.dof {
        return Err(PolicyError::Mismatch(format!(
            "the policy was trained on an arm of dof = {} joints; this run's arm has dof = {}",
            record.dof, config.dof
        )));
    }
    match record.period_ns {
        None => notes
            .push("the policy does not record its period (env.period_ns): not checked".to_string()),
        Some(p) if p != config.period_ns => {
            return Err(PolicyError::Mismatch(format!(
                "the policy was trained at a control period of {p} ns (env.period_ns); \
                 this run's is {} ns",
                config.period_ns
            )));
        }
        Some(_) => {}
    }
    if let Some(note) = other_scenario(record, &config.scenario) {
        notes.push(note);
    }
    let run = serde_json::to_value(&config.params).unwrap_or(Value::Null);
    let Some(trained) = &record.controller else {
        notes.push(
            "the policy does not record its scenario's [controller] (env.controller): not checked"
                .to_string(),
        );
        return Ok(notes);
    };
    let n = record.dof;
    for key in ESSENTIAL {
        // A key the training scenario left out had its default.
        let t = trained
            .get(key)
            .cloned()
            .or_else(|| ControllerParams::default_of(key));
        if let (Some(t), Some(r)) = (t, run.get(key))
            && differs(&t, r, n)
        {
            return Err(PolicyError::Mismatch(format!(
                "the policy was trained with controller.{key} = {t}; this run's controller.{key} is {r}"
            )));
        }
    }
    let mut other = Vec::new();
    let mut keys: Vec<&String> = trained.keys().collect();
    keys.sort();
    for key in keys {
        // Only what the base law reads can change the torque the policy's
        // residual is added to (a pd base takes no torque_bounds, #60
        // item 15); a raw-torque policy has no base law at all.
        let read = record.base_law.is_some_and(|base| base.takes(key));
        if ESSENTIAL.contains(&key.as_str()) || key == "law" || !read {
            continue;
        }
        if let (Some(t), Some(r)) = (trained.get(key), run.get(key))
            && differs(t, r, n)
        {
            other.push(format!("controller.{key} = {r} (trained: {t})"));
        }
    }
    if !other.is_empty() {
        notes.push(format!("this run's {}", other.join(", ")));
    }
    Ok(notes)
}

/// A warning when the record names another scenario than the run's (both
/// by name or file stem; nothing when either is not said).
fn other_scenario(record: &EnvRecord, run: &str) -> Option<String> {
    let trained = record.rest.get("scenario")?.as_str()?;
    let stem = |s: &str| {
        std::path::Path::new(s)
            .file_stem()
            .map_or_else(String::new, |x| x.to_string_lossy().into_owned())
    };
    let trained = stem(trained);
    (!run.is_empty() && !trained.is_empty() && trained != run).then(|| {
        format!("the policy was trained on scenario {trained} (env.scenario); this run's is {run}")
    })
}

/// A per-joint setting (one number, or one per joint) as n numbers.
fn as_joints(v: &Value, n: usize) -> Option<Vec<f64>> {
    match v {
        Value::Number(x) => x.as_f64().map(|x| vec![x; n]),
        Value::Array(xs) if xs.len() == n => xs.iter().map(Value::as_f64).collect(),
        _ => None,
    }
}

fn differs(a: &Value, b: &Value, n: usize) -> bool {
    match (as_joints(a, n), as_joints(b, n)) {
        (Some(x), Some(y)) => x != y,
        _ => a != b,
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;
    use std::path::Path;

    fn record(controller: &str) -> EnvRecord {
        EnvRecord::parse(
            &format!(
                r#"{{"dof": 2, "obs_dim": 15, "steps": 100, "torque_scale": [1.0, 1.0],
                    "period_ns": 1000000, "controller": {controller}}}"#
            ),
            Path::new("p.onnx"),
        )
        .unwrap()
    }

    fn config(k1: f64) -> ControllerNodeConfig {
        let params = ControllerParams {
            law: controller::LawName::Pd,
            ..Default::default()
        };
        let mut v = serde_json::to_value(&params).unwrap();
        v["k1"] = serde_json::json!(k1);
        ControllerNodeConfig {
            params: serde_json::from_value(v).unwrap(),
            dof: 2,
            period_ns: 1_000_000,
            reference_period_ns: 0,
            model: None,
            own_params: Default::default(),
            own_diagnostics: String::new(),
            scenario: String::new(),
        }
    }

    #[test]
    fn a_run_at_other_gains_is_refused_naming_both_values() {
        let e = check_run(&record(r#"{"k1": 3.75}"#), &config(15.0)).unwrap_err();
        let text = e.to_string();
        assert!(text.contains("controller.k1 = 3.75"), "{text}");
        assert!(text.contains("controller.k1 is 15.0"), "{text}");
        assert!(check_run(&record(r#"{"k1": [3.75, 3.75]}"#), &config(3.75)).is_ok());
    }

    #[test]
    fn another_period_or_arm_is_refused() {
        let mut c = config(3.75);
        c.period_ns = 500_000;
        let text = check_run(&record(r#"{"k1": 3.75}"#), &c)
            .unwrap_err()
            .to_string();
        assert!(
            text.contains("1000000 ns") && text.contains("500000 ns"),
            "{text}"
        );
        let mut c = config(3.75);
        c.dof = 3;
        let text = check_run(&record(r#"{"k1": 3.75}"#), &c)
            .unwrap_err()
            .to_string();
        assert!(
            text.contains("dof = 2") && text.contains("dof = 3"),
            "{text}"
        );
    }

    #[test]
    fn another_scenario_is_warned_about() {
        let mut r = record(r#"{"k1": 3.75}"#);
        r.rest
            .insert("scenario".into(), "scenarios/paper_randomised.toml".into());
        let mut c = config(3.75);
        c.scenario = "paper_randomised".into();
        assert!(check_run(&r, &c).unwrap().is_empty());
        c.scenario = "iiwa14_randomised".into();
        let notes = check_run(&r, &c).unwrap();
        assert!(
            notes
                .iter()
                .any(|n| n.contains("scenario paper_randomised") && n.contains("iiwa14")),
            "{notes:?}"
        );
    }

    #[test]
    fn other_settings_the_base_law_reads_are_warned_about() {
        let with_base = |base: &str| {
            let mut r = record(r#"{"k1": 3.75, "beta": 123.0, "torque_bounds": true}"#);
            r.base_law = Some(base.parse().unwrap());
            r
        };
        let notes = check_run(&with_base("nac"), &config(3.75)).unwrap();
        assert!(
            notes.iter().any(|n| n.contains("controller.beta")),
            "{notes:?}"
        );
        // pd reads neither beta nor torque_bounds; a raw-torque policy
        // has no base law to read them.
        assert!(
            check_run(&with_base("pd"), &config(3.75))
                .unwrap()
                .is_empty()
        );
        let raw = record(r#"{"k1": 3.75, "beta": 123.0}"#);
        assert!(check_run(&raw, &config(3.75)).unwrap().is_empty());
    }
}
