//! `testbed bench`: speed and timing on this machine.

use std::process::ExitCode;

use anyhow::Result;

use super::args::BenchArgs;
use crate::report;

pub(crate) fn bench(args: BenchArgs) -> Result<ExitCode> {
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
