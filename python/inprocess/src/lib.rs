//! `testbed._native`: the testbed in process, for Python (PyO3). The
//! Python package `testbed` (beside this crate) wraps it: robots and their
//! dynamics, scenarios with `--set` overrides, `sim` as `testbed sim` runs
//! it, the built-in laws as objects, `compare`, and the Gymnasium
//! environment's core, one arm or many stepped in one call.
//!
//! Where it sits: beside the `testbed` binary, on the same libraries:
//! `sim` is [`run_stack::sim`], the environment is the `gym-env` crate, so
//! a run from Python has the same bits; this crate only converts. No I/O, no
//! IPC; nothing here may panic across the boundary: every error becomes a
//! Python exception that names its cause.

mod convert;
mod env;
mod laws;
mod robot;
mod runs;
mod shipped;

use pyo3::prelude::*;

pyo3::create_exception!(
    _native,
    TestbedError,
    pyo3::exceptions::PyValueError,
    "A scenario, robot or argument the testbed cannot use (the message names the file and key)."
);

/// The module `testbed._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("TestbedError", m.py().get_type::<TestbedError>())?;
    // The package `testbed` is being imported (this module is its
    // `_native`): its folder holds the shipped scenarios and robots.
    if let Ok(dir) = m
        .py()
        .import("sys")
        .and_then(|sys| sys.getattr("modules"))
        .and_then(|mods| mods.get_item("testbed"))
        .and_then(|pkg| pkg.getattr("__path__"))
        .and_then(|path| path.get_item(0))
        .and_then(|dir| dir.extract::<std::path::PathBuf>())
    {
        shipped::set_package_dir(dir);
    }
    m.add("ROBOTS", shipped::robots())?;
    m.add("MAX_DOF", wire::MAX_DOF)?;
    m.add(
        "LAWS",
        controller::LawName::ALL
            .iter()
            .map(|l| l.as_str())
            .collect::<Vec<_>>(),
    )?;
    m.add(
        "SCENARIOS",
        scenario::SHIPPED.iter().map(|s| s.name).collect::<Vec<_>>(),
    )?;
    m.add_class::<robot::Robot>()?;
    m.add_class::<laws::PyLaw>()?;
    m.add_class::<env::EnvCore>()?;
    m.add_class::<env::VecEnvCore>()?;
    m.add_function(wrap_pyfunction!(runs::sim, m)?)?;
    m.add_function(wrap_pyfunction!(runs::compare, m)?)?;
    m.add_function(wrap_pyfunction!(runs::scenario_toml, m)?)?;
    m.add_function(wrap_pyfunction!(runs::search_space, m)?)?;
    m.add_function(wrap_pyfunction!(runs::scenario_file, m)?)?;
    Ok(())
}
