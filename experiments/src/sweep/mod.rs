//! `testbed sweep`: Monte Carlo and parameter grids, in process on every
//! core or as a Slurm job array, into a results folder that resumes.
//!
//! A sweep file ([`file`](mod@file)) is expanded into resolved runs, each exactly
//! what `testbed sim --law L` would run on the scenario with the cell's
//! values and seed; each run's result is one JSON line keyed by a hash of
//! its resolved scenario ([`results`]), so an interrupted sweep, or a
//! resubmitted Slurm array, does only what is missing. [`report`]
//! aggregates a folder per cell; [`slurm`] writes the job array.

pub mod plots;
pub mod report;
pub mod results;
pub mod slurm;

use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::compare;
use results::{Manifest, ResultLine, ResultWriter};
/// The sweep file (parsed and expanded in the scenario crate).
pub use scenario::sweep_file as file;
use scenario::sweep_file::{RunSpec, Sweep, cell_json};

pub use scenario::sweep_file::MAX_FILE_BYTES;

/// Why a sweep could not be run or reported.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The sweep file cannot be used.
    #[error(transparent)]
    File(#[from] scenario::sweep_file::SweepFileError),
    /// A results folder cannot be used.
    #[error("{dir}: {reason}")]
    Folder {
        /// The folder.
        dir: String,
        /// What is wrong.
        reason: String,
    },
    /// Reading or writing failed.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        cause: std::io::Error,
    },
    /// A bad option.
    #[error("{0}")]
    Options(String),
}

/// Reads a file of at most [`MAX_FILE_BYTES`], refusing special files.
pub(crate) fn read_limited(path: &Path) -> Result<String, SweepError> {
    let io = |cause| SweepError::Io {
        path: path.display().to_string(),
        cause,
    };
    wire::read_text_file(path, MAX_FILE_BYTES).map_err(io)
}

/// Which runs this process does and how.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Worker threads (None: one per CPU).
    pub threads: Option<usize>,
    /// This task's index and the number of tasks: runs whose index is
    /// `index` modulo `tasks` (a Slurm array task); None: every run.
    pub share: Option<(usize, usize)>,
    /// Show a progress bar with an ETA.
    pub progress: bool,
}

/// What a `sweep run` did.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// Runs in the sweep.
    pub total: usize,
    /// Runs in this process's share.
    pub mine: usize,
    /// Of those, already in the folder.
    pub done_before: usize,
    /// Run now.
    pub ran: usize,
    /// Of those, failed or diverged.
    pub not_ok: usize,
    /// Stopped by `stop` before the end.
    pub interrupted: bool,
}

/// Runs every missing run of this process's share into `dir`, on all
/// cores, until done or until `stop` is set (each line already written is
/// kept; runs in flight are dropped and done again next time).
pub fn run(
    sweep: &Sweep,
    dir: &Path,
    opts: &RunOptions,
    stop: &AtomicBool,
) -> Result<RunOutcome, SweepError> {
    if let Some((index, tasks)) = opts.share
        && (tasks == 0 || index >= tasks)
    {
        return Err(SweepError::Options(format!(
            "--index {index} --tasks {tasks}: the index must be below the number of tasks"
        )));
    }
    results::open_folder(dir, &Manifest::of(sweep))?;
    let (done, _) = results::read_results(dir)?;
    let mine: Vec<&RunSpec> = sweep
        .runs
        .iter()
        .filter(|r| opts.share.is_none_or(|(i, n)| r.index % n == i))
        .collect();
    let todo: Vec<&RunSpec> = mine
        .iter()
        .copied()
        .filter(|r| !done.contains_key(&r.key))
        .collect();
    let worker = match opts.share {
        Some((i, _)) => format!("task{i}-{}", std::process::id()),
        None => format!("local-{}", std::process::id()),
    };
    let writer = Mutex::new(None::<ResultWriter>);
    let first_error = Mutex::new(None::<SweepError>);
    let (ran, not_ok) = (Mutex::new(0usize), Mutex::new(0usize));
    let bar = crate::progress::bar(opts.progress, todo.len());
    let pool = pool(opts.threads)?;
    pool.install(|| {
        todo.par_iter().for_each(|spec| {
            if stop.load(Ordering::Relaxed) {
                return;
            }
            let Some(line) = execute(spec, stop) else {
                return;
            };
            let ok = line.status == "ok";
            let written = lock(&writer)
                .get_or_insert_with_result(|| ResultWriter::open(dir, &worker))
                .and_then(|w| w.append(&line));
            match written {
                Ok(()) => {
                    *lock(&ran) += 1;
                    *lock(&not_ok) += usize::from(!ok);
                    if let Some(b) = &bar {
                        b.inc(1);
                    }
                }
                Err(e) => {
                    // A full disk, say: stop, keeping what is written.
                    lock(&first_error).get_or_insert(e);
                    stop.store(true, Ordering::Relaxed);
                }
            }
        })
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if let Some(e) = lock(&first_error).take() {
        return Err(e);
    }
    // #39 row 16: a folder removed after the last line was written is as
    // lost as one removed before it.
    if let Some(w) = lock(&writer).as_ref() {
        w.check_still_there()?;
    }
    results::read_manifest(dir)?;
    let ran = *lock(&ran);
    Ok(RunOutcome {
        total: sweep.runs.len(),
        mine: mine.len(),
        done_before: mine.len() - todo.len(),
        ran,
        not_ok: *lock(&not_ok),
        interrupted: ran < todo.len(),
    })
}

/// Opens the writer on first use, so a share with nothing to do leaves no file.
trait GetOrInsertWithResult<T> {
    fn get_or_insert_with_result(
        &mut self,
        f: impl FnOnce() -> Result<T, SweepError>,
    ) -> Result<&mut T, SweepError>;
}

impl<T> GetOrInsertWithResult<T> for Option<T> {
    fn get_or_insert_with_result(
        &mut self,
        f: impl FnOnce() -> Result<T, SweepError>,
    ) -> Result<&mut T, SweepError> {
        if self.is_none() {
            *self = Some(f()?);
        }
        self.as_mut()
            .ok_or_else(|| SweepError::Options("result writer".into()))
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    // A worker that panicked cannot leave a counter half-written.
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool, SweepError> {
    let n = threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| SweepError::Options(format!("cannot start {n} worker threads: {e}")))
}

/// One run, as a result line; None if `stop` cut it short.
pub fn execute(spec: &RunSpec, stop: &AtomicBool) -> Option<ResultLine> {
    let run = compare::run_until(&spec.plan, stop)?;
    let (status, reason) = match (&run.failure, run.summary.finite) {
        (Some(f), _) => ("failed", Some(f.clone())),
        (None, false) => (
            "diverged",
            Some("non-finite values or controller faults".to_string()),
        ),
        (None, true) => ("ok", None),
    };
    let stats = compare::stats_of(&run);
    let metrics = stats
        .0
        .iter()
        .map(|(k, v)| {
            let j = if v.is_finite() {
                serde_json::json!(v)
            } else {
                serde_json::Value::Null
            };
            (k.to_string(), j)
        })
        .collect();
    Some(ResultLine {
        key: spec.key.clone(),
        index: spec.index,
        law: spec.law.to_string(),
        seed: spec.seed,
        cell: cell_json(&spec.cell),
        status: status.into(),
        reason,
        // The comparison's rule: the envelope fact, whatever the status.
        kept_envelope: run.envelope == compare::Envelope::Kept,
        metrics,
        summary: serde_json::to_value(&run.summary).unwrap_or(serde_json::Value::Null),
    })
}
