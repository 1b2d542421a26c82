//! Every process of a run ends with it, a helper that left its node's
//! process group (`setsid`, a daemon) included. Each node is started with
//! [`RUN_ENV`] naming the run; its descendants inherit it, whatever group
//! or session they move to. When the run's nodes are gone, every process
//! that still carries the run's name is killed. (A helper that clears its
//! environment escapes this; docs/guarantees-and-testing.md says so.)

use std::time::{Duration, Instant};

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

/// The variable that names a node's run, inherited by what it starts.
pub const RUN_ENV: &str = "TESTBED_RUN";

/// How long the sweep may take: a `/proc/<pid>/environ` read can block
/// while another process holds that process's memory lock.
const SWEEP_LIMIT: Duration = Duration::from_secs(5);

/// The processes (but this one) whose environment holds `RUN_ENV=run`.
fn carriers(run: &str) -> Vec<i32> {
    let me = std::process::id() as i32;
    let needle = format!("{RUN_ENV}={run}\0").into_bytes();
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    entries
        .flatten()
        .filter_map(|e| e.file_name().to_str()?.parse::<i32>().ok())
        .filter(|&pid| pid != me)
        .filter(|pid| {
            std::fs::read(format!("/proc/{pid}/environ"))
                .is_ok_and(|env| env.windows(needle.len()).any(|w| w == needle.as_slice()))
        })
        .collect()
}

/// Kills every process that carries `run`, until none is left or the
/// limit passes; returns how many were killed.
pub fn end_strays(run: &str) -> usize {
    let run = run.to_string();
    let (tx, rx) = std::sync::mpsc::channel();
    let sweep = std::thread::Builder::new()
        .name("stray-sweep".into())
        .spawn(move || {
            let start = Instant::now();
            let mut killed = 0;
            while start.elapsed() < SWEEP_LIMIT {
                let found = carriers(&run);
                if found.is_empty() {
                    break;
                }
                for pid in found {
                    if kill(Pid::from_raw(pid), Signal::SIGKILL).is_ok() {
                        killed += 1;
                    }
                }
                // A killed process is gone once its parent (or init)
                // reaps it; look again after a moment.
                std::thread::sleep(Duration::from_millis(10));
            }
            let _ = tx.send(killed);
        });
    match sweep {
        Ok(_) => rx.recv_timeout(SWEEP_LIMIT * 2).unwrap_or(0),
        Err(_) => 0,
    }
}
