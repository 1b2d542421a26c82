//! `testbed run`: the stack as separate processes.

use std::io::IsTerminal;
use std::process::ExitCode;

use anyhow::{Context, Result};
use run_stack::run::{self, RunError, RunOptions};

use super::args::RunArgs;
use super::{EXIT_INTERRUPTED, load, print_report};
use analysis::report::Report;

pub(crate) fn run_stack(args: RunArgs, verbose: bool) -> Result<ExitCode> {
    let plan = load(&args.common, args.rate)?;
    if let Some(path) = &args.common.csv {
        let inputs = super::outputs::plan_inputs(args.common.scenario.as_deref(), &plan);
        super::outputs::refuse_input("--csv", path, &inputs)?;
    }
    let source = plan.source.clone();
    let opts = RunOptions {
        plan: plan.clone(),
        mode: args.mode,
        csv: args.common.csv.clone(),
        external: args.external.iter().map(|n| n.kind()).collect(),
        runs_dir: args.runs_dir.clone(),
        name: args.name.clone(),
        progress: std::io::stderr().is_terminal(),
        realtime_setup: !args.no_realtime_setup,
        verbose,
        controller_cmd: args
            .controller_cmd
            .as_deref()
            .map(super::args::command_words)
            .transpose()?,
        log_compression: args.log_compression,
        live: args.live.map(|addr| logger::live::LiveConfig {
            addr,
            rate_hz: args.live_rate,
            max_clients: args.live_clients,
        }),
    };
    let outcome = match run::run(opts) {
        Ok(o) => o,
        Err(RunError::Interrupted) => {
            eprintln!("testbed: interrupted; all nodes stopped");
            return Ok(ExitCode::from(EXIT_INTERRUPTED));
        }
        Err(e) => return Err(e).with_context(|| format!("running {source}")),
    };
    let verdict = outcome.analysis.timing.verdict;
    let mut report = Report::from_log(outcome.analysis);
    report.run_dir = Some(outcome.run_dir.display().to_string());
    print_report(&report, args.common.json)?;
    Ok(super::verdict_status(verdict, "run"))
}
