//! The data of a bench: what it is asked and what it reports. Every other
//! file of `bench` builds on these; this file imports none of them.

use std::path::PathBuf;

use analysis::timing::Percentiles;
use run_stack::node::placement;
use run_stack::run::RunError;
use run_stack::sim;
use serde::Serialize;

/// What to measure.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Length of each real-time part (and of the floor), s.
    pub realtime_s: f64,
    /// Repeats of the in-process and lockstep parts (medians are reported).
    pub repeats: usize,
    /// Folder for the runs' folders.
    pub runs_dir: PathBuf,
    /// Shorten every scenario to this many seconds (for quick checks).
    pub duration_s: Option<f64>,
    /// The largest shipped arm.
    pub large_arm: PathBuf,
    /// Place the nodes as `testbed run` does by default (pinned, and in
    /// real time SCHED_FIFO with locked memory); the timer floor then runs
    /// with the plant's placement, so that the two compare like for like.
    pub realtime_setup: bool,
    /// The logs' chunk compression.
    pub log_compression: logger::LogCompression,
    /// Run this law instead of the scenarios' (None: theirs).
    pub law: Option<controller::LawName>,
}

/// Why a bench failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A scenario could not be loaded.
    #[error(transparent)]
    Scenario(#[from] scenario::ScenarioError),
    /// The in-process loop failed.
    #[error(transparent)]
    Loop(#[from] sim::LoopError),
    /// A multi-process run failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// The Python + MuJoCo loop of `--peer` failed.
    #[error("bench --peer: {0}")]
    Peer(String),
    /// The iceoryx2 ping-pong failed.
    #[error("bench ping-pong: {0}")]
    PingPong(String),
}

/// The machine the bench ran on.
#[derive(Debug, Clone, Serialize)]
pub struct Machine {
    /// CPU model.
    pub cpu: String,
    /// Logical CPUs.
    pub cores: usize,
    /// Kernel release.
    pub kernel: String,
}

/// Real-time figures of one run.
#[derive(Debug, Clone, Serialize)]
pub struct RealtimeFigures {
    /// Plant cycles.
    pub cycles: u64,
    /// Commands that missed their deadline.
    pub deadline_misses: u64,
    /// Plant wake-ups late by a whole period or more: the floor's kind of miss.
    pub late_wakeups: u64,
    /// |actual − nominal period|, µs.
    pub period_jitter_us: Percentiles,
    /// State → command, µs.
    pub round_trip_us: Percentiles,
    /// Samples the logger could not take.
    pub logger_dropped: u64,
}

/// The bare sleep loop: what the machine allows with no IPC and no work.
#[derive(Debug, Clone, Serialize)]
pub struct TimerFloor {
    /// Cycles inside the real-time run's window.
    pub cycles: u64,
    /// Wake-ups later than the next deadline.
    pub deadline_misses: u64,
    /// |actual − nominal period|, µs.
    pub period_jitter_us: Percentiles,
    /// What the system refused of the plant's placement (empty: all applied).
    pub placement_refused: Vec<String>,
}

/// Figures for one arm.
#[derive(Debug, Clone, Serialize)]
pub struct ArmBench {
    /// Scenario name.
    pub scenario: String,
    /// Joints.
    pub dof: usize,
    /// Sim time of one run, s.
    pub sim_s: f64,
    /// In-process loop wall time (median), s.
    pub inprocess_wall_s: f64,
    /// Lockstep stack with the logger, START to last step (median), s.
    pub lockstep_wall_s: f64,
    /// Sim time / lockstep wall time.
    pub lockstep_realtime_factor: f64,
    /// Lockstep wall / in-process wall.
    pub lockstep_to_inprocess_ratio: f64,
    /// The fastest any lockstep over events could be here: steps × the
    /// ping-pong's round trip + the in-process wall, s.
    pub lockstep_floor_s: f64,
    /// Lockstep wall / that floor.
    pub lockstep_to_floor_ratio: f64,
    /// Controller step (median), µs.
    pub controller_step_us: f64,
    /// Plant step (median, all substeps), µs.
    pub plant_step_us: f64,
    /// Real time at the scenario rate.
    pub realtime: RealtimeFigures,
    /// The bare sleep loop over the same window (see `FloorProbe`).
    pub timer_floor: TimerFloor,
    /// Peak resident memory, kB: the in-process loop (this process) and each node.
    pub peak_rss_kb: Vec<(String, u64)>,
    /// CPU time of each node in the first lockstep run, s: where the
    /// lockstep time goes (plant and controller share one CPU).
    pub lockstep_node_cpu_s: Vec<(String, f64)>,
}

/// The whole bench. The top-level figures are the paper scenario's.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Where it ran.
    pub machine: Machine,
    /// Repeats per part.
    pub repeats: usize,
    /// A bare two-process iceoryx2 ping-pong (state out, command back, as
    /// lockstep's plant and controller exchange them), the floor of any
    /// lockstep over events ([`crate::bench::pingpong`]).
    pub pingpong: PingPong,
    /// Whether the nodes were pinned and, in real time, ran under SCHED_FIFO.
    pub realtime_setup: bool,
    /// The paper scenario's figures (its `timer_floor` among them), at the
    /// top level of the JSON.
    #[serde(flatten)]
    pub paper: ArmBench,
    /// Every arm's figures.
    pub arms: Vec<ArmBench>,
}

/// The median (the upper one of an even count; 0 when empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

/// Reads what /proc says about this machine.
pub fn machine() -> Machine {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    Machine {
        cpu,
        cores: placement::cpu_count(),
        kernel: std::fs::read_to_string("/proc/sys/kernel/osrelease")
            .map_or_else(|_| "unknown".into(), |s| s.trim().to_string()),
    }
}

/// What the ping-pong measured.
#[derive(Debug, Clone, Serialize)]
pub struct PingPong {
    /// Round trips timed (after one to connect).
    pub rounds: u64,
    /// Wall time per round trip, µs (the median run's).
    pub round_trip_us: f64,
}
