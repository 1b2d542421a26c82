//! Writes the messages of N lockstep steps of a 2-joint arm (a joint state,
//! a reference sample, a command, the controller's diagnostics and a timing
//! record per step) to an MCAP file, the logger's whole work per step, for
//! instruction counts that do not move with the machine's load:
//! `valgrind --tool=callgrind target/release/examples/log_steps 20000 /tmp/steps.mcap`
//! (a third argument, `zstd`, `lz4` or `none`, picks the compression).

use std::collections::BTreeMap;
use std::path::Path;
use std::process::ExitCode;

use logger::{LogWriter, RunMetadata};
use wire::{Command, ControllerDiagnostics, Header, JointState, ReferenceSample, Timing};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let (Some(steps), Some(out)) = (args.get(1).and_then(|s| s.parse::<u64>().ok()), args.get(2))
    else {
        eprintln!("usage: log_steps STEPS OUT.mcap [zstd|lz4|none]");
        return ExitCode::from(2);
    };
    let compression = match args.get(3).map(|s| logger::LogCompression::parse(s)) {
        None => logger::LogCompression::default(),
        Some(Ok(c)) => c,
        Some(Err(e)) => {
            eprintln!("log_steps: {e}");
            return ExitCode::from(2);
        }
    };
    match run(steps, Path::new(out), compression) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("log_steps: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(
    steps: u64,
    out: &Path,
    compression: logger::LogCompression,
) -> Result<(), logger::LogError> {
    // A scratch file of this benchmark: each run replaces it (the logger
    // itself never overwrites a log).
    if out.is_file() {
        std::fs::remove_file(out).map_err(|cause| logger::LogError::Io {
            path: out.display().to_string(),
            cause,
        })?;
    }
    let mut log = LogWriter::create_with(out, &RunMetadata::default(), "", compression)?;
    for k in 0..steps {
        let t = k as f64 * 1e-3;
        let header = Header {
            seq: k,
            t_ns: k * 1_000_000,
            wall_ns: 1_000_000_000 + k * 17_000,
        };
        let mut s = JointState {
            header,
            ..JointState::default()
        };
        s.q[0] = (2.0 * t).sin() + 0.01 * t.cos();
        s.q[1] = t.cos() - 0.02 * t;
        s.qd[0] = 2.0 * (2.0 * t).cos();
        s.qd[1] = -t.sin();
        let mut r = ReferenceSample {
            header,
            ..ReferenceSample::default()
        };
        r.q_d[0] = (2.0 * t).sin();
        r.q_d[1] = t.cos();
        let mut c = Command {
            header,
            ..Command::default()
        };
        c.tau[0] = 3.0 * t.sin() + 0.123_456_789;
        c.tau[1] = -1.5 * t.cos();
        let mut d = ControllerDiagnostics {
            header,
            ..ControllerDiagnostics::default()
        };
        d.tau = c.tau;
        d.z1[0] = s.q[0] - r.q_d[0];
        d.z1[1] = s.q[1] - r.q_d[1];
        let timing = Timing {
            header,
            round_trip_ns: 12_000 + (k % 97) as i64,
            ..Timing::default()
        };
        log.write(&s)?;
        log.write(&r)?;
        log.write(&c)?;
        log.write(&d)?;
        log.write(&timing)?;
        log.flush_if_due()?;
    }
    log.finish(BTreeMap::new())
}
