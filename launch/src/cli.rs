//! Command-line parsing and dispatch.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};

use launch::{closed_loop, csv_out, summary::SummaryBuilder};
use scenario::Overrides;

use crate::report::{self, SimReport};

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
}

#[derive(Debug, Args)]
struct SimArgs {
    /// Scenario file (TOML) [default: the built-in paper scenario, scenarios/paper.toml].
    #[arg(long, value_name = "FILE")]
    scenario: Option<PathBuf>,
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

/// Parses the command line and runs it.
pub fn run() -> Result<ExitCode> {
    let cli = Cli::parse();
    match cli.command {
        Command::Sim(args) => sim(args),
    }
}

fn sim(args: SimArgs) -> Result<ExitCode> {
    let overrides = Overrides {
        duration_s: args.duration,
    };
    let plan = scenario::load(args.scenario.as_deref(), &overrides)?;
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

    let report = SimReport::new(&plan, summary.finish(), wall);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", report::table(&report));
    }
    if !report.summary.finite {
        eprintln!("testbed: warning: the run produced non-finite values or controller faults");
    }
    Ok(ExitCode::SUCCESS)
}
