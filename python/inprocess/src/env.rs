//! The Gymnasium environment's core (the `gym-env` crate) as Python
//! classes: `EnvCore` (one arm) and `VecEnvCore` (many), which
//! `testbed/env.py` wraps for Gymnasium. Only conversions live here: keyword
//! options read by name, arrays in and out, errors as exceptions.

use std::path::PathBuf;

use gym_env::{ActionMode, ArmEnv, ArmEnvs, Autoreset, EnvOptions, Outcome, ResetOptions};
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};

use crate::convert::{ScenarioArgs, array, err, read_into};

/// The keyword options both classes take, in the order the docs list them.
const KEYWORDS: [&str; 12] = [
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
];

/// Extracts `v` (not None) as a `T`, or a TypeError naming `key` and
/// what it takes.
fn take<'py, T: FromPyObjectOwned<'py>>(
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
fn load(
    class: &str,
    scenario: Option<PathBuf>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<(scenario::Plan, EnvOptions)> {
    let mut opts = EnvOptions::default();
    let (mut robot, mut set, mut episode_s, mut duration) = (None, None, None, None);
    let mut base_law: Option<String> = None;
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
        if v.is_instance_of::<PyBool>() && !matches!(key.as_str(), "safe" | "scale_obs") {
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
            // None for an option whose default is "not given".
            _ => {}
        }
    }
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
fn reset_options(n: usize, options: Option<&Bound<'_, PyDict>>) -> PyResult<ResetOptions> {
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
fn vec_reset_options(
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

/// A picture as an (height, width, 3) uint8 array.
fn picture<'py>(
    py: Python<'py>,
    env: &mut ArmEnv,
    width: usize,
    height: usize,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let px = env.render(width, height).map_err(err)?;
    PyArray1::from_vec(py, px).reshape([height, width, 3])
}

/// One arm's episodes (see `testbed.ArmTrackingEnv` for the contract).
#[pyclass(module = "testbed")]
pub struct EnvCore {
    env: ArmEnv,
    action: Vec<f64>,
    obs: Vec<f64>,
    /// The episode ended (terminated or truncated): step refuses until reset.
    ended: bool,
}

#[pymethods]
impl EnvCore {
    #[new]
    #[pyo3(signature = (scenario=None, **kwargs))]
    fn new(scenario: Option<PathBuf>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let (plan, opts) = load("EnvCore", scenario, kwargs)?;
        let env = ArmEnv::new(plan, opts).map_err(err)?;
        Ok(Self {
            action: vec![0.0; env.dof()],
            obs: vec![0.0; env.obs_dim()],
            env,
            ended: false,
        })
    }

    /// Starts an episode drawn with `seed` (`options`: `initial_q`,
    /// `initial_qd`); returns its first observation.
    #[pyo3(signature = (seed, options=None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let opts = reset_options(self.env.dof(), options)?;
        self.env
            .reset_with(seed, &opts, &mut self.obs)
            .map_err(err)?;
        self.ended = false;
        Ok(array(py, &self.obs))
    }

    /// One step: `(obs, reward, terminated, truncated, {"cost": c})`.
    #[allow(clippy::type_complexity)] // Reason: the tuple is Gymnasium's step return.
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        f64,
        bool,
        bool,
        Bound<'py, PyDict>,
    )> {
        if self.ended {
            return Err(PyRuntimeError::new_err(
                "step() after the episode ended: call reset() first",
            ));
        }
        read_into("action", action, &mut self.action)?;
        check_finite(&self.action, None)?;
        let o = self.env.step(&self.action, &mut self.obs);
        self.ended = o.terminated || o.truncated;
        let info = PyDict::new(py);
        info.set_item(pyo3::intern!(py, "cost"), o.cost)?;
        Ok((
            array(py, &self.obs),
            o.reward,
            o.terminated,
            o.truncated,
            info,
        ))
    }

    /// A picture of the arm (dark) over its reference pose (light): an
    /// (height, width, 3) uint8 array.
    #[pyo3(signature = (width=480, height=480))]
    fn render<'py>(
        &mut self,
        py: Python<'py>,
        width: usize,
        height: usize,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        picture(py, &mut self.env, width, height)
    }

    /// Number of controlled joints.
    #[getter]
    fn dof(&self) -> usize {
        self.env.dof()
    }

    /// Length of the observation.
    #[getter]
    fn obs_dim(&self) -> usize {
        self.env.obs_dim()
    }

    /// Torque per unit of action, per joint.
    #[getter]
    fn torque_scale<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.env.scale())
    }

    /// Velocity per unit of observation, per joint.
    #[getter]
    fn velocity_scale<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.env.velocity_scale())
    }

    /// The commanded torque of the last plant period.
    #[getter]
    fn last_torque<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.env.last_torque())
    }

    /// The true joint state (q, q̇) now.
    #[getter]
    fn true_state<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        let (s, n) = (self.env.state(), self.env.dof());
        (array(py, &s.q[..n]), array(py, &s.qd[..n]))
    }

    /// The decision period, s: `decimation` plant periods.
    #[getter]
    fn dt(&self) -> f64 {
        self.env.plan().dt() * f64::from(self.env.options().decimation)
    }

    /// The plant's period, s.
    #[getter]
    fn plant_dt(&self) -> f64 {
        self.env.plan().dt()
    }

    /// Plant periods per decision.
    #[getter]
    fn decimation(&self) -> u32 {
        self.env.options().decimation
    }

    /// Plant periods in an episode.
    #[getter]
    fn steps(&self) -> u64 {
        self.env.plan().steps
    }

    /// Decisions in an episode.
    #[getter]
    fn decisions(&self) -> u64 {
        self.env.decisions()
    }

    /// The plant period the next action acts at.
    #[getter]
    fn step_index(&self) -> u64 {
        self.env.step_index()
    }

    /// T_c, s: costs count from then on.
    #[getter]
    fn tc(&self) -> f64 {
        self.env.plan().scenario.controller.tc
    }

    /// Safe-RL mode.
    #[getter]
    fn safe(&self) -> bool {
        self.env.options().safe
    }

    /// The observation is scaled.
    #[getter]
    fn scale_obs(&self) -> bool {
        self.env.options().scale_obs
    }

    /// The current episode's seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.env.seed()
    }

    /// The controlled joints' names.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.env.plan().robot.model.joint_names()
    }

    /// The robot's URDF.
    #[getter]
    fn robot(&self) -> String {
        self.env.plan().robot.label()
    }

    /// The episode's scenario as it runs (its seed's draws applied), TOML.
    #[getter]
    fn scenario_toml(&self) -> PyResult<String> {
        self.env.plan().effective_toml().map_err(err)
    }
}

/// Many arms stepped in one call (see `testbed.ArmTrackingVecEnv`).
#[pyclass(module = "testbed")]
pub struct VecEnvCore {
    envs: ArmEnvs,
    n: usize,
    obs: Vec<f64>,
    out: Vec<Outcome>,
    /// The actions, copied out of the caller's array before the GIL is
    /// released (another thread may write that array meanwhile).
    actions: Vec<f64>,
    /// The last observations of episodes that ended (same-step autoreset).
    final_obs: Vec<f64>,
}

#[pymethods]
impl VecEnvCore {
    #[new]
    #[pyo3(signature = (num_envs, scenario=None, num_threads=None, **kwargs))]
    fn new(
        num_envs: usize,
        scenario: Option<PathBuf>,
        num_threads: Option<&Bound<'_, PyAny>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let threads = match num_threads.filter(|v| !v.is_none()) {
            None => gym_env::default_threads(),
            Some(v) if v.is_instance_of::<PyBool>() => {
                return Err(PyTypeError::new_err(
                    "num_threads: expected a whole number, got bool",
                ));
            }
            Some(v) => {
                let t: i64 = take("num_threads", v, "a whole number of threads or None")?;
                usize::try_from(t).map_err(|_| {
                    PyValueError::new_err(format!(
                        "num_threads = {t}: must be from 1 to {}",
                        gym_env::MAX_THREADS
                    ))
                })?
            }
        };
        let (plan, opts) = load("VecEnvCore", scenario, kwargs)?;
        let envs = ArmEnvs::with_threads(plan, opts, num_envs, threads).map_err(err)?;
        let n = envs.envs()[0].dof();
        Ok(Self {
            obs: vec![0.0; num_envs * envs.obs_dim()],
            final_obs: vec![0.0; num_envs * envs.obs_dim()],
            out: vec![Outcome::default(); num_envs],
            actions: vec![0.0; num_envs * n],
            envs,
            n,
        })
    }

    /// Resets environment i with `seed + i` (`options`: `initial_q`,
    /// `initial_qd`, each n numbers for every arm or (num_envs, n), one
    /// row per arm); returns the observations.
    #[pyo3(signature = (seed, options=None))]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let opts = vec_reset_options(self.n, self.out.len(), options)?;
        let (envs, obs) = (&mut self.envs, &mut self.obs);
        py.detach(|| envs.reset_with(seed, &opts, obs))
            .map_err(err)?;
        self.observations(py)
    }

    /// One step of every arm: `(obs, rewards, terminated, truncated,
    /// costs)`, arrays of one row per arm; an arm whose episode ended
    /// resets on the next step (Gymnasium's NEXT_STEP).
    #[allow(clippy::type_complexity)] // Reason: the tuple is Gymnasium's step return.
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        self.step_in(py, actions, Autoreset::NextStep)?;
        self.outcomes(py)
    }

    /// One step of every arm, an arm whose episode ended resetting in the
    /// same step (Stable-Baselines3's convention): `(obs, rewards,
    /// terminated, truncated, costs, final_obs)`, `final_obs` the ended
    /// episodes' last observations (rows of arms that did not end: as
    /// they were).
    #[allow(clippy::type_complexity)] // Reason: the tuple is the step return and the final rows.
    fn step_same<'py>(
        &mut self,
        py: Python<'py>,
        actions: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray2<f64>>,
    )> {
        self.step_in(py, actions, Autoreset::SameStep)?;
        let (obs, r, term, trunc, cost) = self.outcomes(py)?;
        let fin = PyArray1::from_slice(py, &self.final_obs)
            .reshape([self.out.len(), self.envs.obs_dim()])?;
        Ok((obs, r, term, trunc, cost, fin))
    }

    /// A picture of arm `index`: an (height, width, 3) uint8 array.
    #[pyo3(signature = (index=0, width=480, height=480))]
    fn render<'py>(
        &mut self,
        py: Python<'py>,
        index: usize,
        width: usize,
        height: usize,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let count = self.out.len();
        let env = self.envs.envs_mut().get_mut(index).ok_or_else(|| {
            PyValueError::new_err(format!("render: index = {index}: there are {count} arms"))
        })?;
        picture(py, env, width, height)
    }

    /// Number of arms.
    #[getter]
    fn num_envs(&self) -> usize {
        self.out.len()
    }

    /// Joints per arm.
    #[getter]
    fn dof(&self) -> usize {
        self.n
    }

    /// Length of one observation.
    #[getter]
    fn obs_dim(&self) -> usize {
        self.envs.obs_dim()
    }

    /// Torque per unit of action, per joint.
    #[getter]
    fn torque_scale<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.envs.envs()[0].scale())
    }

    /// The decision period, s.
    #[getter]
    fn dt(&self) -> f64 {
        let e = &self.envs.envs()[0];
        e.plan().dt() * f64::from(e.options().decimation)
    }

    /// Plant periods in an episode.
    #[getter]
    fn steps(&self) -> u64 {
        self.envs.envs()[0].plan().steps
    }

    /// Decisions in an episode.
    #[getter]
    fn decisions(&self) -> u64 {
        self.envs.envs()[0].decisions()
    }

    /// Each arm's current episode seed.
    #[getter]
    fn seeds(&self) -> Vec<u64> {
        self.envs.envs().iter().map(ArmEnv::seed).collect()
    }

    /// The threads the arms step on.
    #[getter]
    fn num_threads(&self) -> usize {
        self.envs.threads()
    }

    /// The scenario's T_c, s.
    #[getter]
    fn tc(&self) -> f64 {
        self.envs.envs()[0].plan().scenario.controller.tc
    }

    /// Velocity per unit of observation, per joint.
    #[getter]
    fn velocity_scale<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.envs.envs()[0].velocity_scale())
    }
}

impl VecEnvCore {
    /// Reads `actions` and steps every arm with the GIL released.
    fn step_in(
        &mut self,
        py: Python<'_>,
        actions: &Bound<'_, PyAny>,
        mode: Autoreset,
    ) -> PyResult<()> {
        let count = self.out.len();
        let a: PyReadonlyArray2<'_, f64> = actions
            .cast::<PyArray2<f64>>()
            .map_err(|_| {
                PyTypeError::new_err(format!(
                    "actions: expected a float64 array of shape ({count}, {})",
                    self.n
                ))
            })?
            .readonly();
        if a.shape() != [count, self.n] {
            return Err(PyValueError::new_err(format!(
                "actions: shape {:?}; expected ({count}, {}): one row per arm, one column per joint",
                a.shape(),
                self.n
            )));
        }
        // By index, row after row, whatever the memory order (a Fortran-
        // ordered array's memory is column after column).
        for (dst, src) in self.actions.iter_mut().zip(a.as_array().iter()) {
            *dst = *src;
        }
        check_finite(&self.actions, Some(self.n))?;
        let (envs, obs, fin, out, a) = (
            &mut self.envs,
            &mut self.obs,
            &mut self.final_obs,
            &mut self.out,
            &self.actions,
        );
        py.detach(|| envs.step_with(mode, a, obs, Some(fin), out))
            .map_err(err)
    }

    #[allow(clippy::type_complexity)] // Reason: the tuple is Gymnasium's step return.
    fn outcomes<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        let pick = |f: fn(&Outcome) -> f64| -> Vec<f64> { self.out.iter().map(f).collect() };
        let flag = |f: fn(&Outcome) -> bool| -> Vec<bool> { self.out.iter().map(f).collect() };
        Ok((
            self.observations(py)?,
            PyArray1::from_vec(py, pick(|o| o.reward)),
            PyArray1::from_vec(py, flag(|o| o.terminated)),
            PyArray1::from_vec(py, flag(|o| o.truncated)),
            PyArray1::from_vec(py, pick(|o| o.cost)),
        ))
    }

    fn observations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        PyArray1::from_slice(py, &self.obs).reshape([self.out.len(), self.envs.obs_dim()])
    }
}

/// A NaN or infinite action is refused, naming where it is.
fn check_finite(a: &[f64], row: Option<usize>) -> PyResult<()> {
    match a.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(PyValueError::new_err(match row {
            Some(n) => format!(
                "actions[{}, {}] = {} is not a finite number",
                i / n,
                i % n,
                a[i]
            ),
            None => format!("action[{i}] = {} is not a finite number", a[i]),
        })),
    }
}
