//! `testbed.sim`, `testbed.compare` and `testbed.scenario_toml`: whole
//! runs, as the CLI's commands of the same names make them.

use std::path::PathBuf;
use std::time::Instant;

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use analysis::record::StepRecord;
use analysis::report::Report;
use analysis::summary::SummaryBuilder;
use experiments::compare::{CompareOptions, DEFAULT_LAWS};

use crate::convert::{ScenarioArgs, err, json_to_py};

/// How often a run in process looks for Ctrl-C, in wall time: a reply
/// within a blink, at a few clock reads a step.
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// Every row of a run, one growing column per field.
struct Columns {
    n: usize,
    t: Vec<f64>,
    per_joint: Vec<(&'static str, Vec<f64>)>,
    effects: Vec<u32>,
}

type Field = for<'a> fn(&StepRecord<'a>) -> &'a [f64];

/// The per-joint columns `sim` returns, each read from a step's record.
const JOINT_FIELDS: [(&str, Field); 13] = [
    ("q", |r| r.q),
    ("qd", |r| r.qd),
    ("qdd", |r| r.qdd),
    ("tau", |r| r.tau),
    ("q_d", |r| r.q_d),
    ("qd_d", |r| r.qd_d),
    ("kc", |r| r.kc),
    ("z1", |r| r.z1),
    ("z2", |r| r.z2),
    ("wa_norm", |r| r.wa_norm),
    ("q_measured", |r| r.q_measured),
    ("qd_measured", |r| r.qd_measured),
    ("disturbance", |r| r.disturbance),
];

impl Columns {
    fn new(n: usize, steps: usize) -> Self {
        Self {
            n,
            t: Vec::with_capacity(steps),
            per_joint: JOINT_FIELDS
                .iter()
                .map(|(name, _)| (*name, Vec::with_capacity(steps * n)))
                .collect(),
            effects: Vec::with_capacity(steps),
        }
    }

    fn add(&mut self, r: &StepRecord<'_>) {
        self.t.push(r.t);
        for ((_, col), (_, field)) in self.per_joint.iter_mut().zip(JOINT_FIELDS.iter()) {
            col.extend_from_slice(field(r));
        }
        self.effects.push(r.effects);
    }

    fn into_dict(self, py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        let rows = self.t.len();
        d.set_item("t", PyArray1::from_vec(py, self.t))?;
        for (name, col) in self.per_joint {
            d.set_item(name, PyArray1::from_vec(py, col).reshape([rows, self.n])?)?;
        }
        d.set_item("effects", PyArray1::from_vec(py, self.effects))?;
        Ok(d)
    }
}

/// Runs a scenario in process, as `testbed sim` does, and returns
/// `(rows, summary)`: `rows` a dict of numpy arrays, one row per step
/// (`t`; per joint `q`, `qd`, `qdd`, `tau`, `q_d`, `qd_d`, `kc`, `z1`,
/// `z2`, `wa_norm`, `q_measured`, `qd_measured`, `disturbance`; `effects`),
/// the same bits as `testbed sim --csv`; `summary` the dict `testbed sim
/// --json` prints.
#[pyfunction]
#[pyo3(signature = (scenario=None, *, robot=None, set=None, duration=None, law=None))]
pub fn sim<'py>(
    py: Python<'py>,
    scenario: Option<PathBuf>,
    robot: Option<PathBuf>,
    set: Option<&Bound<'py, PyAny>>,
    duration: Option<f64>,
    law: Option<&str>,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyAny>)> {
    let plan = ScenarioArgs {
        scenario,
        robot,
        set,
        duration,
        law,
    }
    .load()?;
    no_external(&plan)?;
    let n = plan.robot.model.dof();
    check_rows_fit(&plan)?;
    let mut interrupted: Option<PyErr> = None;
    let (columns, report) = py
        .detach(|| {
            let mut columns = Columns::new(n, plan.steps as usize);
            let mut summary = SummaryBuilder::new(
                plan.robot.model.joint_names(),
                plan.dt(),
                plan.scenario.controller.tc,
            )
            .with_gravity(&plan.robot.model);
            let mut costs = run_stack::sim::StepCosts::default();
            let start = Instant::now();
            let mut looked = start;
            run_stack::sim::run_measured(&plan, Some(&mut costs), |r| {
                // Ctrl-C reaches Python only between steps: look every
                // SIGNAL_POLL of wall time. (Every 4096 steps was over a
                // minute where a stiff plant made a step 15 ms.)
                if looked.elapsed() >= SIGNAL_POLL {
                    looked = Instant::now();
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        interrupted = Some(e);
                        return Err(std::io::Error::new(
                            std::io::ErrorKind::Interrupted,
                            "interrupted",
                        ));
                    }
                }
                summary.add(r);
                columns.add(r);
                Ok(())
            })
            .map_err(|e| format!("running {}: {e}", plan.source))?;
            let wall = start.elapsed().as_secs_f64();
            let report =
                Report::from_sim(&plan, summary.finish(), wall, costs.controller_us.finish());
            Ok::<_, String>((columns, report))
        })
        .map_err(|e| interrupted.take().unwrap_or_else(|| err(e)))?;
    Ok((columns.into_dict(py)?, json_to_py(py, &report)?))
}

/// The laws on one scenario and its seeds, scored, as `testbed compare
/// --json` prints them (a dict; `laws` holds each law's row).
///
/// `law_sets`: keys set on one law's runs only, as `--law-set` takes them: a
/// list of `"LAW:controller.KEY=VALUE"` strings, or a dict
/// `{"pd": {"controller.k1": 20.0}}`.
#[pyfunction]
#[pyo3(signature = (scenario=None, *, laws=None, seeds=1, robot=None, set=None, duration=None, threads=None, law_sets=None))]
#[allow(clippy::too_many_arguments)] // Python's keywords, one each
pub fn compare(
    scenario: Option<PathBuf>,
    laws: Option<Vec<String>>,
    seeds: u64,
    robot: Option<PathBuf>,
    set: Option<&Bound<'_, PyAny>>,
    duration: Option<f64>,
    threads: Option<usize>,
    law_sets: Option<&Bound<'_, PyAny>>,
) -> PyResult<Py<PyAny>> {
    let law_sets = crate::convert::law_sets(law_sets)?;
    // The interpreter is attached already (a Python call): this takes its
    // token without one more argument.
    let args = ScenarioArgs {
        scenario,
        robot,
        set,
        duration,
        law: None,
    };
    Python::attach(|py| compare_in(py, &args, laws, seeds, threads, law_sets))
}

/// [`compare`] with the interpreter's token.
fn compare_in(
    py: Python<'_>,
    args: &ScenarioArgs<'_, '_>,
    laws: Option<Vec<String>>,
    seeds: u64,
    threads: Option<usize>,
    law_sets: Vec<experiments::compare::LawSet>,
) -> PyResult<Py<PyAny>> {
    let plan = args.load()?;
    no_external(&plan)?;
    let laws = match laws {
        None => DEFAULT_LAWS.to_vec(),
        Some(l) => l
            .iter()
            .map(|s| s.parse::<controller::LawName>().map_err(err))
            .collect::<PyResult<Vec<_>>>()?,
    };
    if seeds == 0 || threads == Some(0) {
        return Err(err("compare needs at least one seed and one thread"));
    }
    if seeds > experiments::compare::MAX_SEEDS {
        return Err(err(format!(
            "seeds={seeds}: at most {} seeds per law (use a sweep for more)",
            experiments::compare::MAX_SEEDS
        )));
    }
    // More threads than four per CPU only queue (the CLI's cap too).
    let cap = 4 * run_stack::node::placement::cpu_count();
    let threads = threads.map(|t| t.min(cap));
    let opts = CompareOptions {
        law_sets,
        laws,
        seeds,
        threads,
        series: false,
        tuning: None,
        external: Vec::new(),
        runs_dir: std::env::temp_dir(),
        progress: false,
    };
    let result = py
        .detach(|| experiments::compare::compare(&plan, &opts).map_err(|e| e.to_string()))
        .map_err(err)?;
    json_to_py(py, &result).map(Bound::unbind)
}

/// The scenario as it would run (overrides applied), as TOML text.
#[pyfunction]
#[pyo3(signature = (scenario=None, *, robot=None, set=None, duration=None, law=None))]
pub fn scenario_toml<'py>(
    scenario: Option<PathBuf>,
    robot: Option<PathBuf>,
    set: Option<&Bound<'py, PyAny>>,
    duration: Option<f64>,
    law: Option<&str>,
) -> PyResult<String> {
    let plan = ScenarioArgs {
        scenario,
        robot,
        set,
        duration,
        law,
    }
    .load()?;
    plan.effective_toml().map_err(err)
}

/// The keys a tuner searches for `law` (`testbed tune --print-space LAW`):
/// a list of dicts, each with `key`, `role` (gain, law, actor, critic) and
/// `range` (`kind`: float, int, scale or choice, and its bounds).
#[pyfunction]
pub fn search_space(py: Python<'_>, law: &str) -> PyResult<Py<PyAny>> {
    let law: controller::LawName = law.parse().map_err(err)?;
    let space = serde_json::to_value(controller::search_space(law)).map_err(err)?;
    json_to_py(py, &space).map(Bound::unbind)
}

/// The scenario as its author wrote it with `set` applied, as the text of
/// a file to write in folder `dir` (its robot path made relative to
/// `dir`): not the drawn scenario of one seed (`scenario_toml`), so a
/// randomised scenario stays randomised. `testbed tune best
/// --write-scenario` writes its files with it.
#[pyfunction]
#[pyo3(signature = (scenario=None, *, dir, robot=None, set=None))]
pub fn scenario_file<'py>(
    scenario: Option<PathBuf>,
    dir: PathBuf,
    robot: Option<PathBuf>,
    set: Option<&Bound<'py, PyAny>>,
) -> PyResult<String> {
    let plan = ScenarioArgs {
        scenario,
        robot,
        set,
        duration: None,
        law: None,
    }
    .load()?;
    plan.authored_toml_in(&dir).map_err(err)
}

/// The most memory `sim` may hold in rows, bytes.
const MAX_ROWS_BYTES: f64 = 4.0 * 1024.0 * 1024.0 * 1024.0;

/// Refuses a run whose rows would not fit in [`MAX_ROWS_BYTES`].
fn check_rows_fit(plan: &scenario::Plan) -> PyResult<()> {
    let n = plan.robot.model.dof();
    let bytes = plan.steps as f64 * (JOINT_FIELDS.len() * n + 2) as f64 * 8.0;
    if bytes > MAX_ROWS_BYTES {
        return Err(err(format!(
            "{}: {} steps of {n} joints would be {:.1} GB of rows (at most {:.1} GB): \
             shorten the duration, or run `testbed sim --csv` to stream them",
            plan.source,
            plan.steps,
            bytes / 1e9,
            MAX_ROWS_BYTES / 1e9
        )));
    }
    Ok(())
}

/// A scenario with an `[external]` table is for an external controller.
pub fn no_external(plan: &scenario::Plan) -> PyResult<()> {
    match plan.scenario.external.keys().next() {
        Some(key) => Err(err(format!(
            "{}: [external] {key} is for an external controller (`testbed run --controller-cmd`); \
             the in-process module runs the testbed's own laws",
            plan.source
        ))),
        None => Ok(()),
    }
}
