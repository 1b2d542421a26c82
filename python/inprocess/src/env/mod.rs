//! The Gymnasium environment's core (the `gym-env` crate) as Python
//! classes: `EnvCore` (one arm) and `VecEnvCore` (many), which
//! `testbed/env.py` wraps for Gymnasium. Only conversions live here: keyword
//! options read by name, arrays in and out, errors as exceptions.

mod options;
mod single;
mod vector;

pub use single::EnvCore;
pub use vector::VecEnvCore;

use gym_env::ArmEnv;
use numpy::{PyArray1, PyArray3, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::err;

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
