//! `testbed bench`: speed and timing on this machine.

use std::process::ExitCode;

use anyhow::{Context, Result};

use super::args::BenchArgs;
use experiments::bench::table;

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
    let command = args
        .controller_cmd
        .as_deref()
        .map(super::args::command_words)
        .transpose()?;
    let opts = experiments::bench::BenchOptions {
        realtime_s: args.realtime_s,
        repeats: args.repeats,
        runs_dir: args.runs_dir,
        duration_s: args.duration,
        large_arm: args.large_arm,
        realtime_setup: !args.no_realtime_setup,
        log_compression: args.log_compression,
        law: args.law,
    };
    let progress = |what: &str| eprintln!("testbed bench: {what}");
    if args.gym {
        return gym(&args.peer_python, args.repeats, args.json);
    }
    if args.peer {
        let python = super::args::command_words(&args.peer_python)?;
        let report = experiments::bench::peer::run(&opts, &python, progress)?;
        if args.json {
            super::write_stdout(&format!("{}\n", serde_json::to_string_pretty(&report)?))?;
        } else {
            super::write_stdout(&table::peer_table(&report))?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    if let Some(command) = command {
        let report = experiments::bench::controller::run(&opts, &command, progress)?;
        if args.json {
            super::write_stdout(&format!("{}\n", serde_json::to_string_pretty(&report)?))?;
        } else {
            super::write_stdout(&table::controller_table(&report))?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    let report = experiments::bench::run(&opts, progress)?;
    if args.json {
        super::write_stdout(&format!("{}\n", serde_json::to_string_pretty(&report)?))?;
    } else {
        super::write_stdout(&table::bench_table(&report))?;
    }
    Ok(ExitCode::SUCCESS)
}

/// `bench --gym`: the Gymnasium benchmark script, its figures printed as
/// it prints them (a table, or one JSON object).
fn gym(python: &str, repeats: usize, json: bool) -> Result<ExitCode> {
    let words = super::args::command_words(python)?;
    let Some((program, pre)) = words.split_first() else {
        anyhow::bail!("--peer-python: no Python command");
    };
    let script =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/bench/gym_steps.py");
    let mut cmd = std::process::Command::new(program);
    cmd.args(pre)
        .arg(&script)
        .args(["--repeats", &repeats.to_string()]);
    if json {
        cmd.arg("--json");
    }
    eprintln!(
        "testbed bench: Gymnasium environments from Python ({})",
        script.display()
    );
    let out = cmd
        .stderr(std::process::Stdio::inherit())
        .output()
        .with_context(|| format!("cannot start {program}"))?;
    if !out.status.success() {
        anyhow::bail!(
            "{} failed ({}); build the module with `bash python/build-module.sh --release`",
            script.display(),
            out.status
        );
    }
    super::write_stdout(&String::from_utf8_lossy(&out.stdout))?;
    Ok(ExitCode::SUCCESS)
}
