//! The keyword options `EnvCore` and `VecEnvCore` take, read by name into
//! the env's options, and the per-arm reset options.

use std::path::PathBuf;

use gym_env::{ActionMode, EnvOptions, ResetOptions};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};

use crate::convert::{ScenarioArgs, err, read_into};

/// The low-pass's time constant when `smoothing_tau_s` is not given, s:
/// one decision at the default decimation of a 1 kHz plant.
const DEFAULT_SMOOTHING_TAU_S: f64 = 0.02;

/// The keyword options both classes take, in the order the docs list them.
const KEYWORDS: [&str; 16] = [
    "robot",
    "set",
    "episode_s",
    "duration",
    "base_law",
    "residual_scale",
    "effort_weight",
    "breach_factor",
    "torque_scale",
    "decimation",
    "safe",
    "scale_obs",
    "smoothing",
    "smoothing_tau_s",
    "action_rate_weight",
    "observe_action",
];

/// Extracts `v` (not None) as a `T`, or a TypeError naming `key` and
/// what it takes.
pub(super) fn take<'py, T: FromPyObjectOwned<'py>>(
    key: &str,
    v: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<T> {
    v.extract::<T>().map_err(|_| {
        let ty = v
            .get_type()
            .name()
            .map_or_else(|_| "?".into(), |n| n.to_string());
        PyTypeError::new_err(format!("{key}: expected {what}, got {ty}"))
    })
}

/// The scenario and options of `scenario` and the keyword options.
pub(super) fn load(
    class: &str,
    scenario: Option<PathBuf>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<(scenario::Plan, EnvOptions)> {
    let mut opts = EnvOptions::default();
    let (mut robot, mut set, mut episode_s, mut duration) = (None, None, None, None);
    let mut base_law: Option<String> = None;
    let (mut smoothing, mut smoothing_tau_s) = ("hold".to_string(), None::<f64>);
    for (k, v) in kwargs.into_iter().flatten() {
        let key: String = take("keyword", &k, "a string")?;
        if !KEYWORDS.contains(&key.as_str()) {
            return Err(PyTypeError::new_err(format!(
                "{class}() got an unexpected keyword argument '{key}'; it takes {}",
                KEYWORDS.join(", ")
            )));
        }
        let none = v.is_none();
        // A bool is an int to Python: refused where a number is meant.
        if v.is_instance_of::<PyBool>()
            && !matches!(key.as_str(), "safe" | "scale_obs" | "observe_action")
        {
            return Err(PyTypeError::new_err(format!(
                "{key}: expected a number, got bool"
            )));
        }
        match key.as_str() {
            "robot" if !none => robot = Some(take::<PathBuf>(&key, &v, "a path")?),
            "set" if !none => set = Some(v),
            "episode_s" if !none => episode_s = Some(take::<f64>(&key, &v, "a number of seconds")?),
            "duration" if !none => duration = Some(take::<f64>(&key, &v, "a number of seconds")?),
            "base_law" if !none => base_law = Some(take(&key, &v, "a law's name or None")?),
            "residual_scale" => opts.residual_scale = take(&key, &v, "a number")?,
            "effort_weight" => opts.effort_weight = take(&key, &v, "a number")?,
            "breach_factor" => {
                opts.breach_factor = if none {
                    None
                } else {
                    Some(take(&key, &v, "a number or None")?)
                }
            }
            "torque_scale" if !none => {
                opts.torque_scale = Some(take(&key, &v, "a list of numbers, one per joint")?)
            }
            "decimation" => {
                let d: i64 = take(&key, &v, "a whole number of plant periods")?;
                opts.decimation = u32::try_from(d).map_err(|_| {
                    PyValueError::new_err(format!(
                        "decimation = {d}: must be a whole number of plant periods from 1 to 100000"
                    ))
                })?;
            }
            "safe" => opts.safe = take(&key, &v, "True or False")?,
            "scale_obs" => opts.scale_obs = take(&key, &v, "True or False")?,
            "smoothing" if !none => {
                smoothing = take(&key, &v, "\"hold\", \"ramp\" or \"low-pass\"")?
            }
            "smoothing_tau_s" if !none => {
                smoothing_tau_s = Some(take(&key, &v, "a number of seconds")?)
            }
            "action_rate_weight" => opts.action_rate_weight = take(&key, &v, "a number")?,
            "observe_action" => opts.observe_action = take(&key, &v, "True or False")?,
            // None for an option whose default is "not given".
            _ => {}
        }
    }
    if let (Some(tau), false) = (smoothing_tau_s, smoothing == "low-pass") {
        return Err(PyValueError::new_err(format!(
            "smoothing_tau_s = {tau}: only smoothing=\"low-pass\" takes a time constant \
             (smoothing is {smoothing:?})"
        )));
    }
    let tau = smoothing_tau_s.unwrap_or(DEFAULT_SMOOTHING_TAU_S);
    opts.smoothing = gym_env::Smoothing::parse(&smoothing, tau).map_err(err)?;
    let length = match (episode_s, duration) {
        (Some(e), Some(d)) => {
            return Err(PyValueError::new_err(format!(
                "episode_s = {e} and duration = {d}: give one (duration is episode_s's old name)"
            )));
        }
        (Some(e), None) | (None, Some(e)) => e,
        (None, None) => gym_env::DEFAULT_EPISODE_S,
    };
    gym_env::check_episode_s(length).map_err(err)?;
    let plan = ScenarioArgs {
        scenario,
        robot,
        set: set.as_ref(),
        duration: Some(length),
        law: None,
    }
    .load()?;
    crate::runs::no_external(&plan)?;
    if let Some(l) = base_law {
        opts.action = ActionMode::Residual(
            l.parse()
                .map_err(|e| PyValueError::new_err(format!("base_law: {e}")))?,
        );
    }
    Ok((plan, opts))
}

/// `reset`'s `options`: `initial_q` and `initial_qd`, others refused by name.
pub(super) fn reset_options(
    n: usize,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<ResetOptions> {
    let mut out = ResetOptions::default();
    for (k, v) in options.into_iter().flatten() {
        let key: String = take("options key", &k, "a string")?;
        let into = match key.as_str() {
            "initial_q" => &mut out.initial_q,
            "initial_qd" => &mut out.initial_qd,
            _ => {
                return Err(PyValueError::new_err(format!(
                    "reset: option '{key}' is not taken; the options are initial_q and initial_qd"
                )));
            }
        };
        if !v.is_none() {
            let mut x = vec![0.0; n];
            read_into(&key, &v, &mut x)?;
            *into = Some(x);
        }
    }
    Ok(out)
}

/// The vector form's `reset` `options`: as the single env's, each value n
/// numbers for every arm or (num_envs, n) numbers, a row per arm.
pub(super) fn vec_reset_options(
    n: usize,
    count: usize,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<ResetOptions>> {
    let Some(options) = options else {
        return Ok(vec![ResetOptions::default()]);
    };
    let mut out = vec![ResetOptions::default(); count];
    for (k, v) in options.iter() {
        let key: String = take("options key", &k, "a string")?;
        // A row per arm when the value is two-dimensional (an array of
        // two dimensions, or a list of sequences); else one for all.
        let rows: Option<Vec<Bound<'_, PyAny>>> = if v.is_none() {
            None
        } else if let Ok(shape) = v.getattr("shape").and_then(|s| s.extract::<Vec<usize>>()) {
            (shape.len() == 2)
                .then(|| v.try_iter().and_then(|it| it.collect()))
                .transpose()?
        } else {
            v.extract::<Vec<Bound<'_, PyAny>>>()
                .ok()
                .filter(|items| items.first().is_some_and(|x| x.extract::<f64>().is_err()))
        };
        let one = PyDict::new(options.py());
        let Some(rows) = rows else {
            one.set_item(&key, &v)?;
            let o = reset_options(n, Some(&one))?;
            for arm in &mut out {
                merge(arm, &o);
            }
            continue;
        };
        if rows.len() != count {
            return Err(PyValueError::new_err(format!(
                "reset: options['{key}']: {} rows; expected {n} numbers for every arm or {count} rows of {n}, one per arm",
                rows.len()
            )));
        }
        for (arm, row) in out.iter_mut().zip(&rows) {
            one.set_item(&key, row)?;
            merge(arm, &reset_options(n, Some(&one))?);
        }
    }
    Ok(out)
}

/// `from`'s given values into `into`.
fn merge(into: &mut ResetOptions, from: &ResetOptions) {
    if from.initial_q.is_some() {
        into.initial_q.clone_from(&from.initial_q);
    }
    if from.initial_qd.is_some() {
        into.initial_qd.clone_from(&from.initial_qd);
    }
}
