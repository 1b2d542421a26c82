//! `testbed.Robot`: an arm from its URDF as the testbed reads it, with
//! the engine's joint-space dynamics M(q), C(q, q̇) q̇ and G(q) for
//! model-based users.

use std::path::PathBuf;

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use plant_rapier::{ArmModel, Locks, Plant, PlantConfig};

use crate::convert::{array, err, read_finite};

/// An arm loaded from a URDF (`Robot("robots/iiwa14.urdf")`; `Robot()` is
/// the paper's two-link arm), with its locked joints held.
///
/// The dynamics are the articulated engine's, of the rigid arm as the URDF
/// gives it: no joint damping, friction or armature (those are the
/// scenario's plant effects, which the controller does not know).
#[pyclass(module = "testbed", name = "Robot")]
pub struct Robot {
    model: ArmModel,
    label: String,
    plant: Plant,
    n: usize,
}

#[pymethods]
impl Robot {
    /// Loads `urdf` (a file or a shipped robot's name, `"iiwa14"`; None:
    /// the built-in two-link arm) with the joints in
    /// `lock` ({name: position}) held still.
    #[new]
    #[pyo3(signature = (urdf=None, *, lock=None))]
    fn new(urdf: Option<PathBuf>, lock: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut locks = Locks::new();
        if let Some(l) = lock {
            for (k, v) in l.iter() {
                locks.insert(k.extract()?, v.extract()?);
            }
        }
        let urdf = urdf
            .as_deref()
            .map(crate::shipped::robot)
            .transpose()
            .map_err(err)?;
        let source = match &urdf {
            Some(p) => scenario::RobotSource::from_file(p, &locks),
            None => scenario::RobotSource::builtin().relocked(&locks),
        }
        .map_err(err)?;
        let config = PlantConfig {
            urdf_dynamics: false,
            ..PlantConfig::default()
        };
        let plant = Plant::new(&source.model, &config)
            .map_err(|e| err(format!("{}: {e}", source.label())))?;
        Ok(Self {
            n: source.model.dof(),
            label: source.label(),
            model: source.model,
            plant,
        })
    }

    /// The URDF's path (or "built-in two_link.urdf").
    #[getter]
    fn path(&self) -> String {
        self.label.clone()
    }

    /// The robot's name in its URDF.
    #[getter]
    fn name(&self) -> String {
        self.model.name.clone()
    }

    /// Number of controlled joints.
    #[getter]
    fn dof(&self) -> usize {
        self.n
    }

    /// The controlled joints' names, in the order of every array.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.model.joint_names()
    }

    /// Each controlled joint's type ("revolute", "continuous", "prismatic").
    #[getter]
    fn joint_types(&self) -> Vec<&'static str> {
        self.joints().map(|j| j.kind.as_str()).collect()
    }

    /// Lower position limits (rad or m; -inf where the URDF has none).
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .joints()
            .map(|j| j.limits.map_or(f64::NEG_INFINITY, |l| l.0))
            .collect();
        array(py, &v)
    }

    /// Upper position limits (rad or m; +inf where the URDF has none).
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .joints()
            .map(|j| j.limits.map_or(f64::INFINITY, |l| l.1))
            .collect();
        array(py, &v)
    }

    /// Effort limits (N m or N; NaN where the URDF gives none).
    #[getter]
    fn effort<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .joints()
            .map(|j| j.effort.unwrap_or(f64::NAN))
            .collect();
        array(py, &v)
    }

    /// Joints held still: {name: position}.
    #[getter]
    fn locked(&self) -> Vec<(String, f64)> {
        self.model
            .locked
            .iter()
            .map(|l| (l.name.clone(), l.position))
            .collect()
    }

    /// M(q), n × n.
    fn mass_matrix<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (m, _) = self.dynamics(q, None)?;
        PyArray1::from_vec(py, m).reshape([self.n, self.n])
    }

    /// G(q): the torques that hold the arm still at q.
    fn gravity<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (_, g) = self.dynamics(q, None)?;
        Ok(PyArray1::from_vec(py, g))
    }

    /// C(q, q̇) q̇: the Coriolis and centrifugal torques.
    fn coriolis<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (_, h) = self.dynamics(q, Some(qd))?;
        let (_, g) = self.dynamics(q, None)?;
        Ok(PyArray1::from_vec(
            py,
            h.iter().zip(&g).map(|(h, g)| h - g).collect(),
        ))
    }

    /// The bias h(q, q̇) = C(q, q̇) q̇ + G(q), so that M q̈ + h = τ.
    fn bias<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (_, h) = self.dynamics(q, Some(qd))?;
        Ok(PyArray1::from_vec(py, h))
    }

    fn __repr__(&self) -> String {
        format!(
            "Robot({:?}, dof={}, joints={:?})",
            self.label,
            self.n,
            self.model.joint_names()
        )
    }
}

impl Robot {
    fn joints(&self) -> impl Iterator<Item = &plant_rapier::JointInfo> {
        self.model.actuated.iter().map(|&j| &self.model.joints[j])
    }

    /// M(q) row-major and h(q, q̇) (q̇ = 0 when None).
    fn dynamics(
        &mut self,
        q: &Bound<'_, PyAny>,
        qd: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<(Vec<f64>, Vec<f64>)> {
        let (mut qv, mut qdv) = (vec![0.0; self.n], vec![0.0; self.n]);
        read_finite("q", q, &mut qv)?;
        if let Some(qd) = qd {
            read_finite("qd", qd, &mut qdv)?;
        }
        self.plant
            .set_state(&qv, &qdv)
            .map_err(|e| PyValueError::new_err(format!("{}: {e}", self.label)))?;
        let (m, h) = self
            .plant
            .inertia_and_bias()
            .map_err(|e| PyValueError::new_err(format!("{}: {e}", self.label)))?;
        if m.iter().chain(&h).any(|x| !x.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "{}: the dynamics are not finite at q = {qv:?}, qd = {qdv:?} (too large?)",
                self.label
            )));
        }
        Ok((m, h))
    }
}
