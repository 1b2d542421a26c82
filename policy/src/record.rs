//! The environment a policy was trained in, as its ONNX file records it
//! (`metadata_props["testbed.env"]`): the `env` dict of
//! `testbed.policy.LinearPolicy`, read field by field so that a refusal
//! names the field.

use std::path::Path;

use serde_json::{Map, Value};

use crate::PolicyError;

/// The residual scale of a record that does not give one: the
/// environment's default (python `policy_node` reads the same).
const DEFAULT_RESIDUAL_SCALE: f64 = 0.2;

/// What the node needs of the training environment; the rest of the
/// record (scenario, set, episode_s, …) is kept in [`EnvRecord::rest`].
#[derive(Debug, Clone, PartialEq)]
pub struct EnvRecord {
    /// Controlled joints.
    pub dof: usize,
    /// Observation length, 7 · dof + 1 (8 · dof + 1 with `observe_action`).
    pub obs_dim: usize,
    /// Plant periods in a training episode.
    pub steps: u64,
    /// Torque per unit of action, per joint (N m or N).
    pub torque_scale: Vec<f64>,
    /// Plant periods an action is held (default: 1, files from before
    /// decimation).
    pub decimation: u32,
    /// Whether the observation is scaled (default: false).
    pub scale_obs: bool,
    /// Velocity per unit of observation, per joint (default: 1 each; needed
    /// when `scale_obs`).
    pub velocity_scale: Vec<f64>,
    /// The law the action is a residual on (None: the action is the torque).
    pub base_law: Option<controller::LawName>,
    /// The residual's span as a fraction of the torque scale (default 0.2).
    pub residual_scale: f64,
    /// How a decision's torque is spread over its periods (default: held,
    /// files from before smoothing).
    pub smoothing: gym_env::Smoothing,
    /// Whether the last action ends the observation (default: false).
    pub observe_action: bool,
    /// The training scenario's control period, ns (None: not recorded).
    pub period_ns: Option<u64>,
    /// The training scenario's `[controller]` table (None: not recorded).
    pub controller: Option<Map<String, Value>>,
    /// Every other field, as given.
    pub rest: Map<String, Value>,
}

impl EnvRecord {
    /// Parses and checks the record `text` of the file at `path`.
    pub fn parse(text: &str, path: &Path) -> Result<Self, PolicyError> {
        let bad = |field: &str, reason: String| PolicyError::Record {
            path: path.to_path_buf(),
            field: field.into(),
            reason,
        };
        let value: Value =
            serde_json::from_str(text).map_err(|e| bad("", format!("not JSON ({e})")))?;
        let Value::Object(mut map) = value else {
            return Err(bad("", "not a JSON object".into()));
        };
        let mut take = |key: &str| map.remove(key);
        let count = |key: &str, v: Option<Value>| -> Result<u64, PolicyError> {
            match v {
                None => Err(bad(key, "missing".into())),
                Some(v) => v
                    .as_u64()
                    .filter(|&n| n >= 1)
                    .ok_or_else(|| bad(key, format!("{v} is not an integer ≥ 1"))),
            }
        };
        let dof = count("dof", take("dof"))? as usize;
        let obs_dim = count("obs_dim", take("obs_dim"))? as usize;
        let steps = count("steps", take("steps"))?;
        if dof > wire::MAX_DOF {
            return Err(bad(
                "dof",
                format!("{dof} joints; the testbed takes at most {}", wire::MAX_DOF),
            ));
        }
        let observe_action = match take("observe_action") {
            None => false,
            Some(Value::Bool(b)) => b,
            Some(v) => return Err(bad("observe_action", format!("{v} is not true or false"))),
        };
        let want = gym_env::obs_dim_with(dof, observe_action);
        if obs_dim != want {
            let with = if observe_action {
                ", its last action observed,"
            } else {
                ""
            };
            return Err(bad(
                "obs_dim",
                format!("{obs_dim}; an arm of {dof} joints{with} has {want}"),
            ));
        }
        let tau_s = match take("smoothing_tau_s") {
            None | Some(Value::Null) => f64::NAN,
            Some(v) => v
                .as_f64()
                .ok_or_else(|| bad("smoothing_tau_s", format!("{v} is not a number")))?,
        };
        let smoothing = match take("smoothing") {
            None | Some(Value::Null) => gym_env::Smoothing::Hold,
            Some(Value::String(name)) => gym_env::Smoothing::parse(&name, tau_s).map_err(|e| {
                let field = match &e {
                    gym_env::EnvError::Option { name, .. } => name.clone(),
                    _ => "smoothing".into(),
                };
                bad(&field, e.to_string())
            })?,
            Some(v) => return Err(bad("smoothing", format!("{v} is not a smoothing's name"))),
        };
        let numbers = |key: &str, v: Value, positive: bool| -> Result<Vec<f64>, PolicyError> {
            let need = if positive { "positive " } else { "finite " };
            let list = v
                .as_array()
                .ok_or_else(|| bad(key, format!("must be {dof} {need}numbers")))?;
            let xs: Option<Vec<f64>> = list
                .iter()
                .map(|x| {
                    x.as_f64()
                        .filter(|x| x.is_finite() && (!positive || *x > 0.0))
                })
                .collect();
            match xs {
                Some(xs) if xs.len() == dof => Ok(xs),
                _ => Err(bad(key, format!("{v} is not {dof} {need}numbers"))),
            }
        };
        let torque_scale = match take("torque_scale") {
            None => return Err(bad("torque_scale", "missing".into())),
            // Zero or negative: an action that does nothing, or pushes the
            // other way from the one the policy learnt (#60 item 10).
            Some(v) => numbers("torque_scale", v, true)?,
        };
        let decimation = match take("decimation") {
            None => 1,
            Some(v) => u32::try_from(count("decimation", Some(v))?)
                .map_err(|_| bad("decimation", "too large".into()))?,
        };
        // Held longer than an episode: one decision for the whole run.
        if u64::from(decimation) > steps {
            return Err(bad(
                "decimation",
                format!(
                    "{decimation} periods per decision is longer than the episode's {steps} (steps)"
                ),
            ));
        }
        let scale_obs = match take("scale_obs") {
            None => false,
            Some(Value::Bool(b)) => b,
            Some(v) => return Err(bad("scale_obs", format!("{v} is not true or false"))),
        };
        let velocity_scale = match take("velocity_scale") {
            Some(v) => numbers("velocity_scale", v, true)?,
            None if scale_obs => {
                return Err(bad(
                    "velocity_scale",
                    "missing, and scale_obs is true".into(),
                ));
            }
            None => vec![1.0; dof],
        };
        let base_law = match take("base_law") {
            None | Some(Value::Null) => None,
            Some(Value::String(s)) => Some(s.parse().map_err(|e: String| bad("base_law", e))?),
            Some(v) => return Err(bad("base_law", format!("{v} is not a law's name"))),
        };
        let residual_scale = match take("residual_scale") {
            None | Some(Value::Null) => DEFAULT_RESIDUAL_SCALE,
            Some(v) => v
                .as_f64()
                .filter(|x| x.is_finite() && *x > 0.0)
                .ok_or_else(|| bad("residual_scale", format!("{v} is not a positive number")))?,
        };
        let period_ns = match take("period_ns") {
            None | Some(Value::Null) => None,
            Some(v) => Some(count("period_ns", Some(v))?),
        };
        let controller = match take("controller") {
            None | Some(Value::Null) => None,
            Some(Value::Object(m)) => Some(m),
            Some(v) => return Err(bad("controller", format!("{v} is not a table"))),
        };
        Ok(Self {
            dof,
            obs_dim,
            steps,
            torque_scale,
            decimation,
            scale_obs,
            velocity_scale,
            base_law,
            residual_scale,
            smoothing,
            observe_action,
            period_ns,
            controller,
            rest: map,
        })
    }

    /// The factor on a clipped action: 1 for a torque, the residual scale
    /// for a residual (as the environment's `step`).
    pub fn span(&self) -> f64 {
        match self.base_law {
            None => 1.0,
            Some(_) => self.residual_scale,
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    const GOOD: &str = r#"{"dof": 2, "obs_dim": 15, "steps": 4000, "torque_scale": [50.0, 25.0],
        "decimation": 20, "scale_obs": true, "velocity_scale": [1.0, 0.5],
        "base_law": "pd", "residual_scale": 0.2, "period_ns": 1000000,
        "controller": {"tc": 2.0, "k1": 3.75}, "scenario": "paper_randomised", "episode_s": 4.0}"#;

    fn field_of(text: &str) -> String {
        match EnvRecord::parse(text, Path::new("p.onnx")) {
            Err(PolicyError::Record { field, .. }) => field,
            other => panic!("expected a record error, got {other:?}"),
        }
    }

    #[test]
    fn a_full_record_is_read() {
        let r = EnvRecord::parse(GOOD, Path::new("p.onnx")).unwrap();
        assert_eq!((r.dof, r.obs_dim, r.steps, r.decimation), (2, 15, 4000, 20));
        assert_eq!(r.base_law, Some(controller::LawName::Pd));
        assert_eq!(r.span(), 0.2);
        assert_eq!(r.period_ns, Some(1_000_000));
        assert_eq!(r.rest["scenario"], "paper_randomised");
    }

    #[test]
    fn a_smoothed_record_with_its_last_action_observed_is_read() {
        let mut m: Map<String, Value> = serde_json::from_str(GOOD).unwrap();
        for (k, v) in [
            ("smoothing", r#""low-pass""#),
            ("smoothing_tau_s", "0.05"),
            ("observe_action", "true"),
            ("obs_dim", "17"),
        ] {
            m.insert(k.into(), serde_json::from_str(v).unwrap());
        }
        let r = EnvRecord::parse(&Value::Object(m).to_string(), Path::new("p.onnx")).unwrap();
        assert_eq!(r.smoothing, gym_env::Smoothing::LowPass { tau_s: 0.05 });
        assert!(r.observe_action);
    }

    #[test]
    fn an_old_record_reads_as_1_khz_raw_torque() {
        let r = EnvRecord::parse(
            r#"{"dof": 1, "obs_dim": 8, "steps": 10, "torque_scale": [1.0]}"#,
            Path::new("p.onnx"),
        )
        .unwrap();
        assert_eq!((r.decimation, r.scale_obs, r.span()), (1, false, 1.0));
        assert_eq!(
            (r.smoothing, r.observe_action),
            (gym_env::Smoothing::Hold, false)
        );
    }

    #[test]
    fn a_wrong_field_is_named() {
        let with = |k: &str, v: &str| {
            let mut m: Map<String, Value> = serde_json::from_str(GOOD).unwrap();
            m.insert(k.into(), serde_json::from_str(v).unwrap());
            Value::Object(m).to_string()
        };
        assert_eq!(field_of(&with("obs_dim", "14")), "obs_dim");
        assert_eq!(field_of(&with("dof", "0")), "dof");
        assert_eq!(field_of(&with("torque_scale", "[1.0]")), "torque_scale");
        assert_eq!(
            field_of(&with("velocity_scale", "[1.0, 0.0]")),
            "velocity_scale"
        );
        assert_eq!(field_of(&with("base_law", "\"nope\"")), "base_law");
        assert_eq!(field_of(&with("decimation", "1.5")), "decimation");
        // #60 item 10: a torque scale that does nothing or pushes the other
        // way, one decision for the whole episode.
        for bad in ["[0.0, 25.0]", "[-50.0, 25.0]"] {
            assert_eq!(field_of(&with("torque_scale", bad)), "torque_scale");
        }
        assert_eq!(field_of(&with("decimation", "4294967295")), "decimation");
        assert_eq!(field_of(&with("decimation", "4001")), "decimation");
        assert_eq!(field_of(&with("scale_obs", "1")), "scale_obs");
        assert_eq!(field_of(&with("smoothing", "\"spline\"")), "smoothing");
        assert_eq!(
            field_of(&with("smoothing", "\"low-pass\"")),
            "smoothing_tau_s"
        );
        assert_eq!(field_of(&with("observe_action", "true")), "obs_dim");
        assert_eq!(field_of(r#"{"obs_dim": 8}"#), "dof");
        assert_eq!(field_of("[1]"), "");
    }
}
