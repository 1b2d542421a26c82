//! `testbed.Law`: a built-in law as an object that steps on a state and a
//! reference, for users who drive their own loop.

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use controller::{ControllerInput, Diagnostics, Law, LawName};

use crate::convert::{ScenarioArgs, err, read_into};

/// A built-in law with its parameters from a scenario (`Law("nac")`: the
/// paper's scenario; `Law("pd", robot="robots/ur5.urdf")`: the arm's
/// default scenario; `params={"k1": 20.0}` sets `controller.k1`).
///
/// `step(t, q, qd, q_d, qd_d, qdd_d, kc, kc_dot)` returns the torque, as the
/// controller node would publish it for that state and reference sample;
/// `diagnostics` then holds the step's terms (z1, z2, the barrier, the
/// critic...). The networks' weights live in the object: a new one starts
/// from zero weights, as a run does.
#[pyclass(module = "testbed", name = "Law")]
pub struct PyLaw {
    law: Law,
    name: LawName,
    diag: Diagnostics,
    n: usize,
    dt: f64,
    params: controller::ControllerParams,
    buf: [Vec<f64>; 7],
}

#[pymethods]
impl PyLaw {
    #[new]
    #[pyo3(signature = (name, *, scenario=None, robot=None, set=None, params=None))]
    fn new(
        name: &str,
        scenario: Option<PathBuf>,
        robot: Option<PathBuf>,
        set: Option<&Bound<'_, PyAny>>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let law: LawName = name.parse().map_err(err)?;
        let set = merged_set(set, params)?;
        let plan = ScenarioArgs {
            scenario,
            robot,
            set: set.as_ref().map(|s| s.as_any()),
            duration: None,
            law: Some(name),
        }
        .load()?;
        let n = plan.robot.model.dof();
        let model = law.model_based().then_some(&plan.robot.model);
        let params = plan.scenario.controller.clone();
        Ok(Self {
            law: Law::new(&params, n, model).map_err(err)?,
            name: law,
            diag: Diagnostics::new(n),
            n,
            dt: plan.dt(),
            params,
            buf: std::array::from_fn(|_| vec![0.0; n]),
        })
    }

    /// The law's name.
    #[getter]
    fn name(&self) -> &'static str {
        self.name.as_str()
    }

    /// Number of joints.
    #[getter]
    fn dof(&self) -> usize {
        self.n
    }

    /// The control period, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.dt
    }

    /// The `[controller]` keys the law reads (the common ones and its own),
    /// in the scenario file's order.
    #[getter]
    fn keys(&self) -> Vec<&'static str> {
        controller::ControllerParams::KEYS
            .iter()
            .copied()
            .filter(|k| self.name.takes(k))
            .collect()
    }

    /// The law's parameters as the scenario resolved them.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::convert::json_to_py(py, &self.params)
    }

    /// One step: the torque for the measured state (q, qd) at sim time t
    /// and the reference sample (q_d, qd_d, qdd_d, kc, kc_dot):
    /// `step(t, q, qd, q_d, qd_d, qdd_d, kc, kc_dot)`, the seven arrays
    /// taken as a tuple and read by name.
    #[pyo3(signature = (t, *arrays))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        t: f64,
        arrays: &Bound<'py, PyTuple>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let names = ["q", "qd", "q_d", "qd_d", "qdd_d", "kc", "kc_dot"];
        if arrays.len() != names.len() {
            return Err(PyTypeError::new_err(format!(
                "step: expected t and {} arrays ({}), got {}",
                names.len(),
                names.join(", "),
                arrays.len()
            )));
        }
        for ((b, x), what) in self.buf.iter_mut().zip(arrays.iter()).zip(names) {
            read_into(what, &x, b)?;
        }
        let [q, qd, q_d, qd_d, qdd_d, kc, kc_dot] = &self.buf;
        let input = ControllerInput {
            t,
            q,
            qd,
            q_d,
            qd_d,
            qdd_d,
            kc,
            kc_dot,
        };
        self.law.step(self.dt, &input, &mut self.diag);
        Ok(PyArray1::from_slice(py, &self.diag.tau))
    }

    /// The last step's terms: z1, z1g, z2, alpha, kc, d, tau and its parts
    /// (tau_actor, tau_feedback, tau_barrier, tau_model), gamma, gamma_dot,
    /// j_hat, delta, r, wa_norm, wc_norm, barrier_breached, and fault (None,
    /// or why the step published zero torque).
    #[getter]
    fn diagnostics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = &self.diag;
        let out = PyDict::new(py);
        for (k, v) in [
            ("z1", &d.z1),
            ("z1g", &d.z1g),
            ("z2", &d.z2),
            ("alpha", &d.alpha),
            ("kc", &d.kc),
            ("d", &d.d),
            ("tau", &d.tau),
            ("tau_actor", &d.tau_actor),
            ("tau_feedback", &d.tau_feedback),
            ("tau_barrier", &d.tau_barrier),
            ("tau_model", &d.tau_model),
            ("wa_norm", &d.wa_norm),
        ] {
            out.set_item(k, PyArray1::from_slice(py, v))?;
        }
        for (k, v) in [
            ("gamma", d.gamma),
            ("gamma_dot", d.gamma_dot),
            ("j_hat", d.j_hat),
            ("delta", d.delta),
            ("r", d.r),
            ("wc_norm", d.wc_norm),
        ] {
            out.set_item(k, v)?;
        }
        out.set_item("barrier_breached", d.barrier_breached)?;
        out.set_item("fault", d.fault.map(|f| format!("{f:?}")))?;
        Ok(out)
    }

    fn __repr__(&self) -> String {
        format!(
            "Law({:?}, dof={}, dt={})",
            self.name.as_str(),
            self.n,
            self.dt
        )
    }
}

/// `set` with each of `params` as `controller.KEY`.
fn merged_set<'py>(
    set: Option<&Bound<'py, PyAny>>,
    params: Option<&Bound<'py, PyDict>>,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    let (set, params) = match (set, params) {
        (None, None) => return Ok(None),
        (s, p) => (s, p),
    };
    let py = set.map_or_else(|| params.map(|p| p.py()), |s| Some(s.py()));
    let Some(py) = py else { return Ok(None) };
    let out = PyDict::new(py);
    if let Some(s) = set {
        match s.cast::<PyDict>() {
            Ok(d) => out.update(d.as_mapping())?,
            Err(_) => {
                for (k, v) in crate::convert::overrides_set(Some(s))? {
                    out.set_item(k, crate::convert::json_to_py(py, &v)?)?;
                }
            }
        }
    }
    if let Some(p) = params {
        for (k, v) in p.iter() {
            let k: String = k.extract()?;
            out.set_item(format!("controller.{k}"), v)?;
        }
    }
    Ok(Some(out))
}
