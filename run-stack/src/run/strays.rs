//! Every process of a run ends with it, a helper that left its node's
//! process group (`setsid`, a daemon) or cleared its environment (`env -i`)
//! included.
//!
//! Two nets. The launcher is its descendants' child subreaper
//! (`PR_SET_CHILD_SUBREAPER`): a process whose parent exits is re-parented
//! to the launcher, not to init, so nothing a node starts leaves the
//! launcher's process tree, whatever its group, session or environment. A
//! [`RunTree`] notes the run's part of that tree while it runs (the nodes
//! and everything below them, by pid and start time), and when the nodes
//! are gone kills what is left of it. No cgroup is needed (a plain user has
//! none to make). And each node is started with [`RUN_ENV`] naming the run,
//! which its descendants inherit: every process that still carries it is
//! killed too (a process that another subreaper adopted keeps that).

use std::collections::HashSet;
use std::sync::atomic::{AtomicUsize, Ordering};
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

/// Runs this process is launching now; with one, an orphan re-parented
/// to it during that run can only be that run's.
static ACTIVE_RUNS: AtomicUsize = AtomicUsize::new(0);

/// How often a running [`RunTree`] looks at the tree: a few small /proc
/// reads each time.
const NOTE_EVERY: Duration = Duration::from_millis(50);

/// Makes this process the reaper of its orphaned descendants (idempotent;
/// an error leaves only the environment net, as before).
pub fn become_subreaper() {
    let _ = nix::sys::prctl::set_child_subreaper(true);
}

/// A process: its id and start time (clock ticks after boot), which
/// together name it even once the id is reused.
type Proc = (i32, u64);

/// The start time of `pid` and whether it is a zombie, from its stat.
fn stat_of(pid: i32) -> Option<(u64, bool)> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The name may hold spaces and brackets: fields follow the last ')'.
    let rest = &stat[stat.rfind(')')? + 1..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    // Field 3 (state) is the first after the name, field 22 (starttime)
    // the twentieth.
    let zombie = fields.first().is_some_and(|s| *s == "Z");
    Some((fields.get(19)?.parse().ok()?, zombie))
}

/// The children of `pid`, every thread's.
fn children_of(pid: i32) -> Vec<i32> {
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
        return Vec::new();
    };
    tasks
        .flatten()
        .filter_map(|t| std::fs::read_to_string(t.path().join("children")).ok())
        .flat_map(|list| {
            list.split_whitespace()
                .filter_map(|p| p.parse().ok())
                .collect::<Vec<i32>>()
        })
        .collect()
}

/// `pid` and everything below it, each with its start time.
fn subtree(pid: i32, out: &mut Vec<Proc>) {
    let mut stack = vec![pid];
    while let Some(p) = stack.pop() {
        if let Some((start, _)) = stat_of(p) {
            out.push((p, start));
            stack.extend(children_of(p));
        }
    }
}

/// The run's part of this process's tree: its nodes and all they start.
pub struct RunTree {
    /// Every process seen below a node.
    known: HashSet<Proc>,
    /// This process's children before the run began: not the run's.
    before: HashSet<Proc>,
    last: Option<Instant>,
}

impl Default for RunTree {
    fn default() -> Self {
        become_subreaper();
        ACTIVE_RUNS.fetch_add(1, Ordering::SeqCst);
        let before = children_of(std::process::id() as i32)
            .into_iter()
            .filter_map(|p| Some((p, stat_of(p)?.0)))
            .collect();
        Self {
            known: HashSet::new(),
            before,
            last: None,
        }
    }
}

impl Drop for RunTree {
    fn drop(&mut self) {
        ACTIVE_RUNS.fetch_sub(1, Ordering::SeqCst);
    }
}

impl RunTree {
    /// Notes every process below `nodes` (the run's node processes) and
    /// below the processes noted before, at most every [`NOTE_EVERY`]
    /// unless `now`; reaps those re-parented here that have exited.
    pub fn note(&mut self, nodes: &[i32], now: bool) {
        if !now && self.last.is_some_and(|t| t.elapsed() < NOTE_EVERY) {
            return;
        }
        self.last = Some(Instant::now());
        for child in children_of(std::process::id() as i32) {
            let Some((start, zombie)) = stat_of(child) else {
                continue;
            };
            let id = (child, start);
            if nodes.contains(&child) {
                let mut below = Vec::new();
                subtree(child, &mut below);
                self.known.extend(below);
            } else if self.known.contains(&id) {
                if zombie {
                    // An adopted helper that ended: reaped here, its parent.
                    let _ = nix::sys::wait::waitpid(
                        nix::unistd::Pid::from_raw(child),
                        Some(nix::sys::wait::WaitPidFlag::WNOHANG),
                    );
                    continue;
                }
                let mut below = Vec::new();
                subtree(child, &mut below);
                self.known.extend(below);
            }
        }
    }

    /// Once the nodes are gone: kills what is left of the run's tree (and,
    /// while this is the process's only run, any process adopted during
    /// it, which a helper that orphaned itself between two looks is), and
    /// reaps what was adopted, until none is left or the limit passes.
    /// Returns how many were killed.
    pub fn end(&mut self, nodes: &[i32]) -> usize {
        let me = std::process::id() as i32;
        let start = Instant::now();
        let mut killed = 0;
        while start.elapsed() < SWEEP_LIMIT {
            let alone = ACTIVE_RUNS.load(Ordering::SeqCst) == 1;
            let mut targets = Vec::new();
            for child in children_of(me) {
                let Some((t0, _)) = stat_of(child) else {
                    continue;
                };
                let id = (child, t0);
                if nodes.contains(&child) || self.before.contains(&id) {
                    continue;
                }
                if self.known.contains(&id) || alone {
                    subtree(child, &mut targets);
                }
            }
            if targets.is_empty() {
                break;
            }
            for (pid, _) in &targets {
                if kill(Pid::from_raw(*pid), Signal::SIGKILL).is_ok() {
                    killed += 1;
                }
            }
            std::thread::sleep(Duration::from_millis(10));
            // The adopted ones are this process's to reap; their children
            // come here next and are found on the next look.
            for child in children_of(me) {
                if targets.iter().any(|(p, _)| *p == child) {
                    let _ = nix::sys::wait::waitpid(
                        Pid::from_raw(child),
                        Some(nix::sys::wait::WaitPidFlag::WNOHANG),
                    );
                }
            }
        }
        killed
    }
}
