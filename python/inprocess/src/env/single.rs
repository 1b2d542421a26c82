//! `EnvCore`: one arm's episodes as a Python class.

use std::path::PathBuf;

use gym_env::ArmEnv;
use numpy::{PyArray1, PyArray3};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::options::{load, reset_options};
use super::{check_finite, picture};
use crate::convert::{array, err, read_into};

/// A step's return, Gymnasium's: observation, reward, terminated,
/// truncated, `{"cost": c}`.
type StepReturn<'py> = (
    Bound<'py, PyArray1<f64>>,
    f64,
    bool,
    bool,
    Bound<'py, PyDict>,
);

/// One arm's episodes (see `testbed.ArmTrackingEnv` for the contract).
#[pyclass(module = "testbed")]
pub struct EnvCore {
    env: ArmEnv,
    action: Vec<f64>,
    obs: Vec<f64>,
    /// The episode ended (terminated or truncated): step refuses until reset.
    ended: bool,
    /// No reset yet: Gymnasium's contract is reset before the first step
    /// (#60 item 11: a step before it ran an episode nobody started).
    fresh: bool,
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
            fresh: true,
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
        self.fresh = false;
        Ok(array(py, &self.obs))
    }

    /// One step: `(obs, reward, terminated, truncated, {"cost": c})`.
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: &Bound<'py, PyAny>,
    ) -> PyResult<StepReturn<'py>> {
        if self.fresh {
            return Err(PyRuntimeError::new_err(
                "step() before reset(): call reset() first (Gymnasium's order)",
            ));
        }
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

    /// How a decision's torque is spread over its periods: "hold", "ramp"
    /// or "low-pass".
    #[getter]
    fn smoothing(&self) -> &'static str {
        self.env.options().smoothing.name()
    }

    /// The low-pass's time constant, s (None for "hold" and "ramp").
    #[getter]
    fn smoothing_tau_s(&self) -> Option<f64> {
        self.env.options().smoothing.tau_s()
    }

    /// The last action ends the observation.
    #[getter]
    fn observe_action(&self) -> bool {
        self.env.options().observe_action
    }

    /// Weight of the reward's action-rate term.
    #[getter]
    fn action_rate_weight(&self) -> f64 {
        self.env.options().action_rate_weight
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
