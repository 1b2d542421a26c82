//! `testbed sweep run|report|slurm`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use experiments::sweep::{self, RunOptions, file, report, slurm};

#[derive(Debug, Subcommand)]
pub(crate) enum SweepCommand {
    /// Run every missing run of a sweep file in process, on every core.
    Run(SweepRunArgs),
    /// Aggregate a results folder per cell: median, IQR, worst, success rate.
    Report(SweepReportArgs),
    /// Write the manifest and an sbatch job-array script for a Slurm cluster.
    Slurm(SweepSlurmArgs),
}

#[derive(Debug, Args)]
pub(crate) struct SweepRunArgs {
    /// The sweep file (TOML).
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// Results folder (default: `runs/sweep-<name>`).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Worker threads [default: one per CPU].
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Run only the runs whose index is I modulo --tasks (a Slurm array task).
    #[arg(long, value_name = "I", requires = "tasks")]
    index: Option<usize>,
    /// The number of tasks sharing the sweep (with --index).
    #[arg(long, value_name = "N", requires = "index")]
    tasks: Option<usize>,
    /// No progress bar.
    #[arg(long)]
    no_progress: bool,
}

#[derive(Debug, Args)]
pub(crate) struct SweepReportArgs {
    /// The results folder.
    #[arg(value_name = "DIR")]
    dir: PathBuf,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Write one row per cell to this CSV file.
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Write box plots (and a heat map for a two-axis grid) here.
    #[arg(long, value_name = "DIR")]
    plots: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub(crate) struct SweepSlurmArgs {
    /// The sweep file (TOML).
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// Results folder, shared by the tasks (default: `runs/sweep-<name>`).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Array tasks [default: one per run, at most 1000; more than the runs
    /// are cut to one per run, with a note].
    #[arg(long, value_name = "N")]
    tasks: Option<usize>,
    /// Tasks running at once (the array's %M).
    #[arg(long, value_name = "M", default_value_t = 16)]
    max_running: usize,
    /// CPUs per task (at most 1024).
    #[arg(long, value_name = "C", default_value_t = 1)]
    cpus_per_task: usize,
    /// Slurm partition.
    #[arg(long)]
    partition: Option<String>,
    /// Time limit per task (Slurm's format, e.g. 00:30:00).
    #[arg(long)]
    time: Option<String>,
    /// The testbed binary the tasks run [default: this one].
    #[arg(long, value_name = "PATH")]
    testbed: Option<PathBuf>,
}

pub(crate) fn sweep(cmd: SweepCommand) -> Result<ExitCode> {
    match cmd {
        SweepCommand::Run(a) => run(a),
        SweepCommand::Report(a) => report_cmd(a),
        SweepCommand::Slurm(a) => slurm_cmd(a),
    }
}

fn out_dir(out: Option<PathBuf>, s: &file::Sweep) -> PathBuf {
    out.unwrap_or_else(|| Path::new("runs").join(format!("sweep-{}", s.name)))
}

fn run(a: SweepRunArgs) -> Result<ExitCode> {
    if a.threads == Some(0) {
        bail!("--threads 0: a sweep needs at least one thread");
    }
    let s = file::load(&a.file)?;
    let dir = out_dir(a.out, &s);
    // Ctrl-C (or Slurm's SIGTERM) stops at the next step; lines written stay.
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, Arc::clone(&stop))
            .context("installing the Ctrl-C handler")?;
    }
    let opts = RunOptions {
        threads: super::worker_threads(a.threads),
        share: a.index.zip(a.tasks),
        progress: !a.no_progress,
    };
    let o = sweep::run(&s, &dir, &opts, &stop)
        .with_context(|| format!("sweep {}", a.file.display()))?;
    eprintln!(
        "testbed: sweep {}: {} runs; this share {}: {} done before, {} run now ({} failed or diverged); results in {}",
        s.name,
        o.total,
        o.mine,
        o.done_before,
        o.ran,
        o.not_ok,
        dir.display()
    );
    if o.interrupted {
        eprintln!("testbed: stopped; run the same command again to resume");
        return Ok(ExitCode::from(super::EXIT_INTERRUPTED));
    }
    Ok(ExitCode::SUCCESS)
}

fn report_cmd(a: SweepReportArgs) -> Result<ExitCode> {
    let r = report::report(&a.dir).with_context(|| format!("reading {}", a.dir.display()))?;
    if let Some(path) = &a.csv {
        super::outputs::refuse_input("--csv", path, &super::outputs::files_in(&a.dir))?;
        std::fs::write(path, report::csv(&r))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(dir) = &a.plots {
        let n = sweep::plots::write_all(dir, &r)
            .with_context(|| format!("writing figures to {}", dir.display()))?;
        eprintln!("testbed: wrote {n} figures to {}", dir.display());
    }
    if a.json {
        super::write_stdout(&format!("{}\n", serde_json::to_string_pretty(&r)?))?;
    } else {
        super::write_stdout(&report::table(&r))?;
    }
    if r.found_runs < r.total_runs {
        eprintln!(
            "testbed: warning: {} of {} runs have no result yet",
            r.total_runs - r.found_runs,
            r.total_runs
        );
    }
    Ok(ExitCode::SUCCESS)
}

fn slurm_cmd(a: SweepSlurmArgs) -> Result<ExitCode> {
    let s = file::load(&a.file)?;
    let dir = out_dir(a.out, &s);
    let testbed = match a.testbed {
        Some(p) => p,
        None => std::env::current_exe().context("finding this testbed binary")?,
    };
    let opts = slurm::SlurmOptions {
        tasks: a.tasks,
        max_running: a.max_running,
        cpus_per_task: a.cpus_per_task,
        partition: a.partition,
        time: a.time,
        testbed,
    };
    let w = slurm::write(&s, &dir, &opts)?;
    if let Some(note) = &w.note {
        eprintln!("testbed: note: {note}");
    }
    super::write_stdout(&format!("{}\n", w.path.display()))?;
    eprintln!(
        "testbed: {} runs in {} array tasks, {} missing; submit with: sbatch {}",
        s.runs.len(),
        w.tasks,
        w.missing,
        w.path.display()
    );
    Ok(ExitCode::SUCCESS)
}
