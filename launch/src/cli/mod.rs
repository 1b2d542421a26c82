//! Command-line parsing and dispatch: one module per subcommand.

mod args;
mod bench;
mod compare;
mod outputs;
mod replay;
mod robot;
mod run;
mod scenarios;
mod sim;
mod sweep;
mod tune;

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand, ValueEnum};

use run_stack::node::{self, NodeArgs};
use scenario::Overrides;
use wire::NodeKind;

use analysis::report::{self, Report};
use args::{BenchArgs, CompareArgs, ReplayArgs, RunArgs, ScenarioArgs, SimArgs, TuneArgs};

/// Run the paper's RL neuroadaptive controller under deferred constraints on
/// a simulated arm.
#[derive(Debug, Parser)]
#[command(name = "testbed", version, about)]
struct Cli {
    /// Show iceoryx2's own messages (by default only its errors).
    #[arg(long, global = true)]
    verbose: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run the closed loop in one process, as fast as the machine allows.
    ///
    /// Prints the run's summary on standard output (a table, or one JSON
    /// object with --json); writes nothing else unless asked: --csv FILE
    /// (one row per step), --plots DIR (figures). No log: use `run --mode
    /// lockstep` for one (the same bits).
    Sim(SimArgs),
    /// Run the stack as separate processes over iceoryx2 shared memory.
    ///
    /// Writes the run's folder under --runs-dir (`runs/<id>/` or `runs/NAME/`
    /// with --name: scenario.toml, run.mcap, the Foxglove layout, each
    /// node's config and output in nodes/) and prints the summary with a
    /// timing verdict on standard output; node messages go to standard
    /// error. Exit
    /// status: 0 ran, verdict clean; 1 could not run; 2 bad command line;
    /// 3 ran, verdict degraded (missed commands, stale references, late
    /// wake-ups); 4 ran, verdict invalid (rows or a node lost, the run
    /// unfinished); 130 interrupted.
    Run(RunArgs),
    /// Describe an arm: joints in order, limits, masses, and the default
    /// scenario `--robot` would run on it; or why it cannot be used.
    ///
    /// Prints on standard output; --write-scenario FILE also writes the
    /// default scenario as TOML.
    Robot {
        /// The URDF file.
        #[arg(value_name = "URDF")]
        path: PathBuf,
        /// Also write the default scenario to FILE as TOML, to edit and run
        /// with `testbed sim --scenario FILE` (its `robot` key names the URDF).
        #[arg(long, value_name = "FILE")]
        write_scenario: Option<PathBuf>,
        /// Replace FILE of --write-scenario if it exists (a symbolic link
        /// is never written through).
        #[arg(long, requires = "write_scenario")]
        force: bool,
    },
    /// Measure speed and timing on this machine: in process, lockstep, real
    /// time, and the machine's own timer floor.
    ///
    /// Prints a table (or JSON) on standard output; its runs' folders go
    /// under --runs-dir.
    Bench(BenchArgs),
    /// The other side of `bench`'s iceoryx2 ping-pong (started by `bench`).
    #[command(name = "bench-pong", hide = true)]
    BenchPong {
        /// The ping's run prefix.
        #[arg(long)]
        prefix: String,
        /// Where to run (as lockstep's controller).
        #[command(flatten)]
        placement: run_stack::node::placement::Placement,
    },
    /// Analyse a run's log: the same summary as `run`, CSV, figures, verification.
    ///
    /// Prints the summary on standard output; --csv FILE and --plots DIR
    /// write there. The log is only read.
    Replay(ReplayArgs),
    /// Run several laws (the paper's, its ablations, baselines) on the same
    /// scenario and seeds, in process on every core, and score them.
    ///
    /// Prints the table (or JSON) on standard output; --csv FILE and
    /// --plots DIR write there; progress goes to standard error on a
    /// terminal.
    Compare(CompareArgs),
    /// Monte Carlo and parameter grids: run a sweep file on every core or
    /// on a Slurm cluster, and report it per cell.
    ///
    /// Results go to the folder given by --out (default runs/sweep-NAME),
    /// one JSON line per run; `sweep report` prints on standard output.
    #[command(subcommand)]
    Sweep(sweep::SweepCommand),
    /// Tune a law's parameters: Optuna's TPE over the in-process core, the
    /// same budget and search space rules for every law (docs/tuning.md).
    ///
    /// `--print-space LAW` prints a law's search space; everything else is
    /// `python -m testbed.tune` (run, report, best, evaluate), whose
    /// studies are Optuna journal files several processes may share.
    Tune(TuneArgs),
    /// List the shipped scenarios and what each one demonstrates (on
    /// standard output).
    Scenarios {
        /// One JSON array instead: each scenario's name, file and text.
        #[arg(long)]
        json: bool,
    },
    /// Write the wire contract for another language, generated from the
    /// Rust types (today: Python ctypes structures for the package in python/).
    Bindings {
        /// The language.
        #[arg(value_enum)]
        lang: BindingsLang,
        /// Write here instead of to standard output.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// Write the Foxglove layout for an arm (the paper's five figures, the
    /// timing and the arm in 3D); `testbed run` writes one into each run's
    /// folder, and foxglove/testbed-layout.json is the paper arm's.
    Layout {
        /// The arm's URDF [default: the paper's two-link arm].
        #[arg(long, value_name = "URDF")]
        robot: Option<PathBuf>,
        /// Write here instead of to standard output.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// Run one node of a stack (the launcher starts these; start one by hand
    /// with `testbed run --external <node>` to debug or replace it).
    Node {
        /// Which node.
        #[arg(value_enum)]
        name: NodeName,
        #[command(flatten)]
        args: NodeArgs,
    },
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum BindingsLang {
    Python,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum NodeName {
    Plant,
    Trajectory,
    Controller,
    Logger,
}

impl NodeName {
    pub(crate) fn kind(self) -> NodeKind {
        match self {
            NodeName::Plant => NodeKind::Plant,
            NodeName::Trajectory => NodeKind::Trajectory,
            NodeName::Controller => NodeKind::Controller,
            NodeName::Logger => NodeKind::Logger,
        }
    }
}

/// Exit status of a run stopped by Ctrl-C (128 + SIGINT).
pub(crate) const EXIT_INTERRUPTED: u8 = 130;
/// Exit status of `run` when the run finished but its timing verdict is
/// `degraded` (0: clean; 1: could not run; 2: bad command line).
pub(crate) const EXIT_DEGRADED: u8 = 3;
/// Exit status of `run` when the run's verdict is `invalid`.
pub(crate) const EXIT_INVALID: u8 = 4;

/// The exit status of a verdict (`run`'s and `replay`'s alike), said on
/// stderr when it is not clean: one meaning per status, so that scripts
/// can tell a trustworthy result from one that is not (docs: running).
/// `what` is "run" or "log".
pub(crate) fn verdict_status(verdict: analysis::timing::Verdict, what: &str) -> ExitCode {
    use analysis::timing::Verdict;
    let code = match verdict {
        Verdict::Clean => return ExitCode::SUCCESS,
        Verdict::Degraded => EXIT_DEGRADED,
        Verdict::Invalid => EXIT_INVALID,
    };
    eprintln!(
        "testbed: the {what}'s timing verdict is {} (exit status {code})",
        verdict.as_str()
    );
    ExitCode::from(code)
}

/// Parses the command line and runs it.
pub fn run() -> Result<ExitCode> {
    let cli = Cli::parse();
    bus::set_ipc_log_level(cli.verbose);
    match cli.command {
        Command::Sim(args) => sim::sim(args),
        Command::Run(args) => run::run_stack(args, cli.verbose),
        Command::Replay(args) => replay::replay(args),
        Command::Bench(args) => bench::bench(args),
        Command::BenchPong { prefix, placement } => {
            experiments::bench::pingpong::pong(&prefix, &placement)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Compare(args) => compare::compare(args),
        Command::Sweep(cmd) => sweep::sweep(cmd),
        Command::Tune(args) => tune::tune(args),
        Command::Bindings { lang, out } => {
            let BindingsLang::Python = lang;
            let text = wire::bindings::python();
            match out {
                Some(path) => std::fs::write(&path, text)
                    .with_context(|| format!("writing {}", path.display()))?,
                None => write_stdout(&text)?,
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Layout { robot, out } => {
            let text = robot::layout(robot.as_deref())?;
            match out {
                Some(path) => std::fs::write(&path, text)
                    .with_context(|| format!("writing {}", path.display()))?,
                None => write_stdout(&text)?,
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Scenarios { json } => {
            let text = if json {
                scenarios::scenario_json()?
            } else {
                scenarios::scenario_list()
            };
            write_stdout(&text)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Robot {
            path,
            write_scenario,
            force,
        } => {
            if let Some(out) = &write_scenario {
                robot::write_scenario(&path, out, force)?;
            }
            write_stdout(&robot::describe(&path)?)?;
            if let Some(out) = &write_scenario {
                eprintln!("testbed: default scenario written to {}", out.display());
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Node { name, args } => {
            node::run(name.kind(), &args)
                .with_context(|| format!("{} node", name.kind().name()))?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

pub(crate) fn load(common: &ScenarioArgs, rate: Option<f64>) -> Result<scenario::Plan> {
    let overrides = Overrides {
        duration_s: common.duration,
        rate_hz: rate,
        robot: common.robot.clone(),
        law: common.law,
        set: common.set.clone(),
    };
    let mut plan = scenario::load_named(common.scenario.as_deref(), &overrides)?;
    let effort =
        scenario::effort_warnings(&plan).map_err(|cause| scenario::ScenarioError::Plant {
            file: plan.source.clone(),
            cause,
        })?;
    plan.changes.extend(effort);
    // Said before the run: what the testbed changed beyond the files, and
    // where the scenario asks a motor for more than it can give.
    for line in &plan.changes {
        eprintln!("testbed: note: {line}");
    }
    Ok(plan)
}

/// Refuses a scenario with an `[external]` table where no external
/// controller runs (`sim`, `compare`): its values would be ignored.
pub(crate) fn no_external(plan: &scenario::Plan, command: &str) -> Result<()> {
    if let Some(key) = plan.scenario.external.keys().next() {
        anyhow::bail!(
            "{}: [external] {key} is for an external controller (`testbed run --controller-cmd`); \
             `testbed {command}` runs the testbed's own laws",
            plan.source
        );
    }
    Ok(())
}

pub(crate) fn print_report(report: &Report, json: bool) -> Result<()> {
    if json {
        write_stdout(&format!("{}\n", serde_json::to_string_pretty(report)?))?;
    } else {
        write_stdout(&report::table(report))?;
    }
    if !report.summary.finite {
        eprintln!("testbed: warning: the run produced non-finite values or controller faults");
    }
    if let Some(w) = &report.warning {
        eprintln!("testbed: warning: {w}");
    }
    Ok(())
}

/// Worker threads for `compare` and `sweep run`: at most four per CPU
/// (more only queue; twenty thousand once kept a run from ending for over
/// a minute), said on stderr when the request is cut.
pub(crate) fn worker_threads(requested: Option<usize>) -> Option<usize> {
    let cpus = run_stack::node::placement::cpu_count();
    let cap = 4 * cpus;
    match requested {
        Some(n) if n > cap => {
            eprintln!("testbed: --threads {n} is more than 4 per CPU; using {cap} ({cpus} CPUs)");
            Some(cap)
        }
        other => other,
    }
}

/// Standard output was closed by its reader (`… | head`): the command ends
/// quietly with 141, the status a shell gives a process SIGPIPE ended.
#[derive(Debug, thiserror::Error)]
#[error("standard output was closed")]
pub(crate) struct StdoutClosed;

/// Exit status after [`StdoutClosed`].
pub(crate) const EXIT_STDOUT_CLOSED: u8 = 141;

/// Writes `text` to standard output: a closed pipe is [`StdoutClosed`],
/// any other failure (a full device) a named error; never a panic.
pub(crate) fn write_stdout(text: &str) -> Result<()> {
    use std::io::Write;
    let mut o = std::io::stdout().lock();
    match o.write_all(text.as_bytes()).and_then(|()| o.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(StdoutClosed.into()),
        Err(e) => Err(anyhow::Error::new(e).context("writing to standard output")),
    }
}
