//! Command-line parsing and dispatch.

use std::fs::File;
use std::io::{BufWriter, IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};

use launch::mode::Mode;
use launch::node::{self, NodeArgs};
use launch::run::{self, RunError, RunOptions};
use launch::{closed_loop, csv_out, summary::SummaryBuilder};
use scenario::Overrides;
use wire::NodeKind;

use crate::report::{self, Report};

/// Run the paper's RL neuroadaptive controller under deferred constraints on
/// a simulated arm.
#[derive(Debug, Parser)]
#[command(name = "testbed", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run the closed loop in one process, as fast as the machine allows.
    Sim(SimArgs),
    /// Run the stack as separate processes over iceoryx2 shared memory.
    Run(RunArgs),
    /// Describe an arm: joints in order, limits, masses, and the default
    /// scenario `--robot` would run on it; or why it cannot be used.
    Robot {
        /// The URDF file.
        #[arg(value_name = "URDF")]
        path: PathBuf,
    },
    /// Measure speed and timing on this machine: in process, lockstep, real
    /// time, and the machine's own timer floor.
    Bench(BenchArgs),
    /// Analyse a run's log: the same summary as `run`, CSV, figures, verification.
    Replay(ReplayArgs),
    /// List the shipped scenarios and what each one demonstrates.
    Scenarios,
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
enum NodeName {
    Plant,
    Trajectory,
    Controller,
    Logger,
}

impl NodeName {
    fn kind(self) -> NodeKind {
        match self {
            NodeName::Plant => NodeKind::Plant,
            NodeName::Trajectory => NodeKind::Trajectory,
            NodeName::Controller => NodeKind::Controller,
            NodeName::Logger => NodeKind::Logger,
        }
    }
}

#[derive(Debug, Args)]
struct ScenarioArgs {
    /// Scenario file (TOML), or the name of a shipped one (`testbed
    /// scenarios` lists them) [default: the paper's, scenarios/paper.toml].
    #[arg(long, value_name = "FILE|NAME")]
    scenario: Option<PathBuf>,
    /// Run this arm (URDF) instead of the scenario's; with no --scenario,
    /// the default scenario for the arm (see `testbed robot`).
    #[arg(long, value_name = "URDF")]
    robot: Option<PathBuf>,
    /// Run for this many seconds instead of the scenario's duration_s.
    #[arg(long, value_name = "S")]
    duration: Option<f64>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Write one row per control step to this CSV file.
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
}

#[derive(Debug, Args)]
struct SimArgs {
    #[command(flatten)]
    common: ScenarioArgs,
}

#[derive(Debug, Args)]
struct RunArgs {
    #[command(flatten)]
    common: ScenarioArgs,
    /// Timing mode.
    #[arg(long, value_enum, default_value = "realtime")]
    mode: Mode,
    /// Control rate in Hz instead of the scenario's rate_hz.
    #[arg(long, value_name = "HZ")]
    rate: Option<f64>,
    /// Do not start this node; wait for one started by hand (repeatable).
    #[arg(long, value_enum, value_name = "NODE")]
    external: Vec<NodeName>,
    /// Folder for run folders.
    #[arg(long, value_name = "DIR", default_value = "runs")]
    runs_dir: PathBuf,
    /// Leave the nodes where the OS puts them: no CPU pinning, and in real
    /// time no SCHED_FIFO and no locked memory.
    #[arg(long)]
    no_realtime_setup: bool,
}

#[derive(Debug, Args)]
struct BenchArgs {
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Length of each real-time part and of the timer floor, s.
    #[arg(long, value_name = "S", default_value_t = 60.0)]
    realtime_s: f64,
    /// Repeats of the in-process and lockstep parts (medians are reported).
    #[arg(long, value_name = "N", default_value_t = 3)]
    repeats: usize,
    /// Shorten every scenario to this many seconds (quick check).
    #[arg(long, value_name = "S")]
    duration: Option<f64>,
    /// The large arm to measure besides the paper's: the largest shipped
    /// arm whose default scenario runs at 1 kHz (robots/iiwa14.urdf has 7
    /// joints, but its default scenario runs at 5.2 kHz).
    #[arg(long, value_name = "URDF", default_value = "robots/ur5.urdf")]
    large_arm: PathBuf,
    /// Folder for run folders.
    #[arg(long, value_name = "DIR", default_value = "runs")]
    runs_dir: PathBuf,
    /// Measure without pinning, SCHED_FIFO or locked memory.
    #[arg(long)]
    no_realtime_setup: bool,
}

#[derive(Debug, Args)]
struct ReplayArgs {
    /// The run's MCAP log (runs/<id>/run.mcap).
    #[arg(value_name = "FILE.mcap")]
    log: PathBuf,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Write one row per control step to this CSV file.
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Write the paper's figures (PNG and SVG) and a timing figure here.
    #[arg(long, value_name = "DIR")]
    plots: Option<PathBuf>,
    /// Re-drive the controller from the logged states and references and
    /// report the largest difference from the logged torques.
    #[arg(long)]
    verify: bool,
}

/// Exit status of a run stopped by Ctrl-C (128 + SIGINT).
const EXIT_INTERRUPTED: u8 = 130;

/// Parses the command line and runs it.
pub fn run() -> Result<ExitCode> {
    let cli = Cli::parse();
    match cli.command {
        Command::Sim(args) => sim(args),
        Command::Run(args) => run_stack(args),
        Command::Replay(args) => replay(args),
        Command::Bench(args) => bench(args),
        Command::Scenarios => {
            print!("{}", scenario_list());
            Ok(ExitCode::SUCCESS)
        }
        Command::Robot { path } => {
            print!("{}", crate::robot_info::describe(&path)?);
            Ok(ExitCode::SUCCESS)
        }
        Command::Node { name, args } => {
            node::run(name.kind(), &args)
                .with_context(|| format!("{} node", name.kind().name()))?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn load(common: &ScenarioArgs, rate: Option<f64>) -> Result<scenario::Plan> {
    let overrides = Overrides {
        duration_s: common.duration,
        rate_hz: rate,
        robot: common.robot.clone(),
    };
    let path = common.scenario.as_deref().map(resolve_scenario);
    Ok(scenario::load(path.as_deref(), &overrides)?)
}

/// A scenario argument that is not a file but names a shipped scenario
/// becomes that scenario's file.
fn resolve_scenario(arg: &std::path::Path) -> PathBuf {
    if arg.exists() || arg.components().count() > 1 {
        return arg.to_path_buf();
    }
    match arg.to_str().and_then(scenario::find_shipped) {
        Some(s) => s.path(),
        None => arg.to_path_buf(),
    }
}

/// `testbed scenarios`: name, file and what each shipped scenario shows.
fn scenario_list() -> String {
    let mut out = String::new();
    for s in scenario::SHIPPED {
        out.push_str(&format!("{}\n    {}\n", s.name, s.path().display()));
        let mut line = String::from("   ");
        for word in s.about().split_whitespace() {
            if line.len() + word.len() > 76 {
                out.push_str(&line);
                out.push('\n');
                line = String::from("   ");
            }
            line.push(' ');
            line.push_str(word);
        }
        out.push_str(&line);
        out.push_str("\n\n");
    }
    out.push_str("Run one with `testbed sim --scenario NAME` or `testbed run --scenario NAME`.\n");
    out
}

fn print_report(report: &Report, json: bool) -> Result<()> {
    if json {
        println!("{}", serde_json::to_string_pretty(report)?);
    } else {
        print!("{}", report::table(report));
    }
    if !report.summary.finite {
        eprintln!("testbed: warning: the run produced non-finite values or controller faults");
    }
    if let Some(w) = &report.warning {
        eprintln!("testbed: warning: {w}");
    }
    Ok(())
}

fn sim(args: SimArgs) -> Result<ExitCode> {
    let args = args.common;
    let plan = load(&args, None)?;
    let mut csv = match &args.csv {
        Some(path) => {
            let file = File::create(path)
                .with_context(|| format!("cannot create CSV file {}", path.display()))?;
            let mut w = BufWriter::new(file);
            writeln!(w, "{}", csv_out::header(plan.robot.model.dof()))
                .with_context(|| format!("writing {}", path.display()))?;
            Some(w)
        }
        None => None,
    };
    let mut summary = SummaryBuilder::new(
        plan.robot.model.joint_names(),
        plan.dt(),
        plan.scenario.controller.tc,
    );
    let start = Instant::now();
    let result = closed_loop::run(&plan, |r| {
        summary.add(r);
        match csv.as_mut() {
            Some(w) => csv_out::write_row(w, r),
            None => Ok(()),
        }
    });
    let wall = start.elapsed().as_secs_f64();
    // Keep what was written even if the loop failed part-way.
    if let (Some(mut w), Some(path)) = (csv, &args.csv) {
        w.flush()
            .with_context(|| format!("writing {}", path.display()))?;
    }
    result.with_context(|| format!("running {}", plan.source))?;
    print_report(&Report::from_sim(&plan, summary.finish(), wall), args.json)?;
    Ok(ExitCode::SUCCESS)
}

fn run_stack(args: RunArgs) -> Result<ExitCode> {
    let plan = load(&args.common, args.rate)?;
    let source = plan.source.clone();
    let opts = RunOptions {
        plan: plan.clone(),
        mode: args.mode,
        csv: args.common.csv.clone(),
        external: args.external.iter().map(|n| n.kind()).collect(),
        runs_dir: args.runs_dir.clone(),
        progress: std::io::stderr().is_terminal(),
        realtime_setup: !args.no_realtime_setup,
    };
    let outcome = match run::run(opts) {
        Ok(o) => o,
        Err(RunError::Interrupted) => {
            eprintln!("testbed: interrupted; all nodes stopped");
            return Ok(ExitCode::from(EXIT_INTERRUPTED));
        }
        Err(e) => return Err(e).with_context(|| format!("running {source}")),
    };
    let mut report = Report::from_log(outcome.analysis);
    report.run_dir = Some(outcome.run_dir.display().to_string());
    print_report(&report, args.common.json)?;
    Ok(ExitCode::SUCCESS)
}

fn replay(args: ReplayArgs) -> Result<ExitCode> {
    let mut csv = match &args.csv {
        Some(path) => {
            Some(BufWriter::new(File::create(path).with_context(|| {
                format!("cannot create CSV file {}", path.display())
            })?))
        }
        None => None,
    };
    let csv_name = args
        .csv
        .as_ref()
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    let analysis = launch::analysis::analyse(
        &args.log,
        launch::analysis::AnalyseOptions {
            csv: csv
                .as_mut()
                .map(|w| (csv_name.as_str(), w as &mut dyn Write)),
            verify: args.verify,
            series: args.plots.is_some(),
        },
    )?;
    if let (Some(dir), Some(series)) = (&args.plots, &analysis.series) {
        let written = launch::plots::write_all(dir, series, &analysis.plan)
            .with_context(|| format!("writing figures to {}", dir.display()))?;
        eprintln!("testbed: wrote {} figures to {}", written, dir.display());
    }
    print_report(&Report::from_log(analysis), args.json)?;
    Ok(ExitCode::SUCCESS)
}

fn bench(args: BenchArgs) -> Result<ExitCode> {
    if !(args.realtime_s.is_finite() && args.realtime_s > 0.0) {
        anyhow::bail!(
            "--realtime-s {} is invalid: it must be a number of seconds > 0",
            args.realtime_s
        );
    }
    if args.repeats == 0 {
        anyhow::bail!("--repeats 0 is invalid: it must be at least 1");
    }
    let opts = launch::bench::BenchOptions {
        realtime_s: args.realtime_s,
        repeats: args.repeats,
        runs_dir: args.runs_dir,
        duration_s: args.duration,
        large_arm: args.large_arm,
        realtime_setup: !args.no_realtime_setup,
    };
    let report = launch::bench::run(&opts, |what| eprintln!("testbed bench: {what}"))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", report::bench_table(&report));
    }
    Ok(ExitCode::SUCCESS)
}
