//! The environment's core as Python classes: `EnvCore` (one arm) and
//! `VecEnvCore` (many), which `testbed/gym.py` wraps for Gymnasium.

use std::path::PathBuf;

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::core::{ActionMode, ArmEnv, ArmEnvs, EnvOptions, Outcome};
use crate::convert::{ScenarioArgs, array, err, read_into};

/// The options both classes take, read from Python.
#[allow(clippy::too_many_arguments)]
fn load(
    scenario: Option<PathBuf>,
    robot: Option<PathBuf>,
    set: Option<&Bound<'_, PyAny>>,
    duration: Option<f64>,
    base_law: Option<&str>,
    residual_scale: f64,
    effort_weight: f64,
    breach_factor: Option<f64>,
    torque_scale: Option<Vec<f64>>,
) -> PyResult<(scenario::Plan, EnvOptions)> {
    let plan = ScenarioArgs {
        scenario,
        robot,
        set,
        duration,
        law: None,
    }
    .load()?;
    crate::runs::no_external(&plan)?;
    let action = match base_law {
        None => ActionMode::Torque,
        Some(l) => ActionMode::Residual(
            l.parse()
                .map_err(|e| PyValueError::new_err(format!("base_law: {e}")))?,
        ),
    };
    Ok((
        plan,
        EnvOptions {
            action,
            residual_scale,
            effort_weight,
            breach_factor,
            torque_scale,
        },
    ))
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
    #[pyo3(signature = (scenario=None, *, robot=None, set=None, duration=None, base_law=None,
                        residual_scale=0.2, effort_weight=0.01, breach_factor=Some(2.0),
                        torque_scale=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        scenario: Option<PathBuf>,
        robot: Option<PathBuf>,
        set: Option<&Bound<'_, PyAny>>,
        duration: Option<f64>,
        base_law: Option<&str>,
        residual_scale: f64,
        effort_weight: f64,
        breach_factor: Option<f64>,
        torque_scale: Option<Vec<f64>>,
    ) -> PyResult<Self> {
        let (plan, opts) = load(
            scenario,
            robot,
            set,
            duration,
            base_law,
            residual_scale,
            effort_weight,
            breach_factor,
            torque_scale,
        )?;
        let env = ArmEnv::new(plan, opts).map_err(err)?;
        Ok(Self {
            action: vec![0.0; env.dof()],
            obs: vec![0.0; env.obs_dim()],
            env,
            ended: false,
        })
    }

    /// Starts an episode drawn with `seed`; returns its first observation.
    fn reset<'py>(&mut self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.env.reset(seed, &mut self.obs).map_err(err)?;
        self.ended = false;
        Ok(array(py, &self.obs))
    }

    /// One step: `(obs, reward, terminated, truncated, {"cost": c})`.
    #[allow(clippy::type_complexity)]
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
            return Err(pyo3::exceptions::PyRuntimeError::new_err(
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

    /// The commanded torque of the last step.
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

    /// Control period, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.env.plan().dt()
    }

    /// Steps in an episode.
    #[getter]
    fn steps(&self) -> u64 {
        self.env.plan().steps
    }

    /// The step the next action acts at.
    #[getter]
    fn step_index(&self) -> u64 {
        self.env.step_index()
    }

    /// T_c, s: costs count from then on.
    #[getter]
    fn tc(&self) -> f64 {
        self.env.plan().scenario.controller.tc
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
}

#[pymethods]
impl VecEnvCore {
    #[new]
    #[pyo3(signature = (num_envs, scenario=None, *, robot=None, set=None, duration=None,
                        base_law=None, residual_scale=0.2, effort_weight=0.01,
                        breach_factor=Some(2.0), torque_scale=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        num_envs: usize,
        scenario: Option<PathBuf>,
        robot: Option<PathBuf>,
        set: Option<&Bound<'_, PyAny>>,
        duration: Option<f64>,
        base_law: Option<&str>,
        residual_scale: f64,
        effort_weight: f64,
        breach_factor: Option<f64>,
        torque_scale: Option<Vec<f64>>,
    ) -> PyResult<Self> {
        let (plan, opts) = load(
            scenario,
            robot,
            set,
            duration,
            base_law,
            residual_scale,
            effort_weight,
            breach_factor,
            torque_scale,
        )?;
        let envs = ArmEnvs::new(plan, opts, num_envs).map_err(err)?;
        let n = envs.envs()[0].dof();
        Ok(Self {
            obs: vec![0.0; num_envs * envs.obs_dim()],
            out: vec![Outcome::default(); num_envs],
            actions: vec![0.0; num_envs * n],
            envs,
            n,
        })
    }

    /// Resets environment i with `seed + i`; returns the observations.
    fn reset<'py>(&mut self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.envs.reset(seed, &mut self.obs).map_err(err)?;
        self.observations(py)
    }

    /// One step of every arm: `(obs, rewards, terminated, truncated,
    /// costs)`, arrays of one row per arm.
    #[allow(clippy::type_complexity)]
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
        let count = self.out.len();
        let a: PyReadonlyArray2<'py, f64> = actions
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
        let a = a
            .as_slice()
            .map_err(|_| PyValueError::new_err("actions: must be C-contiguous"))?;
        check_finite(a, Some(self.n))?;
        self.actions.copy_from_slice(a);
        let (envs, obs, out, a) = (&mut self.envs, &mut self.obs, &mut self.out, &self.actions);
        py.detach(|| envs.step(a, obs, out)).map_err(err)?;
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

    /// Control period, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.envs.envs()[0].plan().dt()
    }

    /// Steps in an episode.
    #[getter]
    fn steps(&self) -> u64 {
        self.envs.envs()[0].plan().steps
    }

    /// Each arm's current episode seed.
    #[getter]
    fn seeds(&self) -> Vec<u64> {
        self.envs.envs().iter().map(ArmEnv::seed).collect()
    }
}

impl VecEnvCore {
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
