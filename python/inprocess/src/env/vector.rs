//! `VecEnvCore`: many arms stepped in one call, as a Python class.

use std::path::PathBuf;

use gym_env::{ArmEnv, ArmEnvs, Autoreset, Outcome};
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};

use super::options::{load, take, vec_reset_options};
use super::{check_finite, picture};
use crate::convert::{array, err};

/// A vector step's return, Gymnasium's: observations, rewards,
/// terminated, truncated, costs.
type StepReturn<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<f64>>,
);

/// [`StepReturn`] and the ended episodes' last observations.
type SameStepReturn<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
);

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
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: &Bound<'py, PyAny>,
    ) -> PyResult<StepReturn<'py>> {
        self.step_in(py, actions, Autoreset::NextStep)?;
        self.outcomes(py)
    }

    /// One step of every arm, an arm whose episode ended resetting in the
    /// same step (Stable-Baselines3's convention): `(obs, rewards,
    /// terminated, truncated, costs, final_obs)`, `final_obs` the ended
    /// episodes' last observations (rows of arms that did not end: as
    /// they were).
    fn step_same<'py>(
        &mut self,
        py: Python<'py>,
        actions: &Bound<'py, PyAny>,
    ) -> PyResult<SameStepReturn<'py>> {
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

    fn outcomes<'py>(&self, py: Python<'py>) -> PyResult<StepReturn<'py>> {
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
