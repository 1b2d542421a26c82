//! `testbed bench`: speed and timing on this machine.

use std::fmt::Write;
use std::process::ExitCode;

use anyhow::{Context, Result};
use experiments::bench::controller::ControllerBench;

use super::args::BenchArgs;
use analysis::report::percentiles;
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
            super::write_stdout(&peer_table(&report))?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    if let Some(command) = command {
        let report = experiments::bench::controller::run(&opts, &command, progress)?;
        if args.json {
            super::write_stdout(&format!("{}\n", serde_json::to_string_pretty(&report)?))?;
        } else {
            super::write_stdout(&controller_table(&report))?;
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

/// The lockstep stack against the Python + MuJoCo loop, pair by pair.
fn peer_table(b: &experiments::bench::peer::PeerBench) -> String {
    let mut s = format!(
        "{} scenario, {:.1} s simulated; Python + MuJoCo (RK4, {} substeps) against `testbed run --mode lockstep` (logger on)\n",
        b.scenario, b.sim_s, b.peer_substeps
    );
    let _ = writeln!(
        s,
        "{:<6} {:>14} {:>14} {:>8}",
        "pair", "lockstep, s", "Python, s", "ratio"
    );
    for (i, (l, p)) in b.lockstep_wall_s.iter().zip(&b.peer_wall_s).enumerate() {
        let _ = writeln!(s, "{:<6} {l:>14.3} {p:>14.3} {:>7.1}×", i + 1, p / l);
    }
    let _ = writeln!(
        s,
        "median ratio: {:.1}× (lockstep {:.0}× real time)",
        b.speedup,
        b.sim_s / experiments::bench::median(b.lockstep_wall_s.clone())
    );
    let _ = writeln!(
        s,
        "max |q − q_d| after T_c: testbed {:?}, Python loop {:?} rad",
        b.testbed_max_error_after_tc, b.peer_max_error_after_tc
    );
    s
}

/// The two controllers' figures, pair by pair.
fn controller_table(b: &ControllerBench) -> String {
    let mut out = String::new();
    let m = &b.machine;
    let _ = writeln!(
        out,
        "machine: {} ({} CPUs), kernel {}\n{} with law {} in real time at {} Hz, {} pair(s) of {} s runs",
        m.cpu, m.cores, m.kernel, b.scenario, b.law, b.rate_hz, b.pairs, b.realtime_s
    );
    for (i, pair) in b.testbed.iter().zip(&b.command).enumerate() {
        let _ = writeln!(out, "\npair {}:", i + 1);
        for c in [pair.0, pair.1] {
            let r = &c.realtime;
            let _ = writeln!(
                out,
                "  {}\n    {} cycles, {} deadline misses, {} wake-ups late by a period \
                 (timer floor beside it: {} late)",
                c.controller,
                r.cycles,
                r.deadline_misses,
                r.late_wakeups,
                c.timer_floor.deadline_misses
            );
            let _ = writeln!(
                out,
                "    round trip us     {}",
                percentiles(&r.round_trip_us)
            );
            let _ = writeln!(out, "    compute us        {}", percentiles(&c.compute_us));
            let _ = writeln!(
                out,
                "    period jitter us  {}",
                percentiles(&r.period_jitter_us)
            );
            let _ = writeln!(
                out,
                "    floor jitter us   {}",
                percentiles(&c.timer_floor.period_jitter_us)
            );
        }
    }
    out
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
