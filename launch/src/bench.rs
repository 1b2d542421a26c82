//! `testbed bench`: how fast and how steady the testbed is on this machine.
//!
//! For the paper scenario and the largest shipped arm it measures the
//! in-process loop, the full stack in lockstep with the logger, and the full
//! stack in real time; and, beside each real-time run (same window, same
//! CPU, same priority), the floor the machine sets: a bare absolute-deadline
//! sleep loop with no IPC and no work. On a shared VM the host, not the
//! code, sets the timing tail, and it changes from minute to minute, so the
//! testbed's figures are reported beside a floor measured at the same time.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use scenario::{Overrides, Plan};
use serde::Serialize;

use crate::mode::Mode;
use crate::node::placement::{self, Placement};
use crate::run::{self, RunError, RunOptions};
use crate::sim::{self, StepCosts};
use analysis::timing::{Percentiles, TimingStats};
use bus::clock;
use wire::NodeKind;

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
    /// lockstep over events ([`crate::bench_pingpong`]).
    pub pingpong: crate::bench_pingpong::PingPong,
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

/// A bare absolute-deadline sleep loop (no IPC, no work) in a thread of its
/// own, running while the testbed's real-time run does: the floor is
/// measured in the same window, on the loop's CPU, just above the loop's
/// priority, with deadlines on the plant's grid: both timers fire at the
/// same instants, so the host treats them alike.
struct FloorProbe {
    stop: Arc<AtomicBool>,
    period_ns: u64,
    handle: std::thread::JoinHandle<ProbeRecord>,
}

/// Every (deadline, wake-up) in ns, and what the system refused of the placement.
type ProbeRecord = (Vec<(u64, u64)>, Vec<String>);

impl FloorProbe {
    fn start(rate_hz: f64, max_seconds: f64, placement: &Placement) -> Self {
        let period_ns = (1e9 / rate_hz).round() as u64;
        let stop = Arc::new(AtomicBool::new(false));
        let placement = placement.clone();
        let flag = Arc::clone(&stop);
        // Every wake-up is kept (deadline, wake); the buffer is allocated
        // up front so the loop itself never allocates.
        let capacity = (max_seconds * rate_hz).ceil() as usize + 1;
        let handle = std::thread::spawn(move || {
            let refused = placement.apply();
            clock::tighten_timer_slack();
            let mut wakes = Vec::with_capacity(capacity);
            // The plant's grid: its epoch is a whole multiple of the period.
            let epoch = (clock::monotonic_ns() + period_ns).div_ceil(period_ns) * period_ns;
            for k in 0..capacity as u64 {
                if flag.load(Ordering::Relaxed) {
                    break;
                }
                let deadline = epoch + k * period_ns;
                clock::sleep_until(deadline);
                wakes.push((deadline, clock::monotonic_ns()));
            }
            (wakes, refused)
        });
        Self {
            stop,
            period_ns,
            handle,
        }
    }

    /// Stops the loop; the figures of `cycles` deadlines from the one the
    /// run's first wake-up (`first_wake_ns`) belongs to. Counting deadlines,
    /// not a wall-clock window, keeps a late last wake-up of the run from
    /// adding periods to the floor.
    fn finish(self, first_wake_ns: u64, cycles: u64, rate_hz: f64) -> TimerFloor {
        self.stop.store(true, Ordering::Relaxed);
        let (wakes, refused) = self.handle.join().unwrap_or_default();
        let period = self.period_ns;
        let first_deadline = first_wake_ns / period * period;
        let mut stats = TimingStats::new(period);
        let mut last: Option<u64> = None;
        for &(deadline, wake) in wakes
            .iter()
            .filter(|(d, _)| *d >= first_deadline)
            .take(usize::try_from(cycles).unwrap_or(usize::MAX))
        {
            stats.add(&wire::Timing {
                wake_late_ns: wake as i64 - deadline as i64,
                period_ns: last.map_or(0, |l| (wake - l) as i64),
                round_trip_ns: -1,
                controller_compute_ns: -1,
                ..wire::Timing::default()
            });
            last = Some(wake);
        }
        let t = stats.finish(Mode::Realtime, rate_hz, None);
        TimerFloor {
            cycles: t.cycles,
            deadline_misses: t.late_wakeups,
            period_jitter_us: t.period_jitter_us,
            placement_refused: refused,
        }
    }
}

pub(crate) fn load(robot: Option<&Path>, opts: &BenchOptions) -> Result<Plan, BenchError> {
    Ok(scenario::load(
        None,
        &Overrides {
            duration_s: opts.duration_s,
            rate_hz: None,
            robot: robot.map(Path::to_path_buf),
            law: opts.law,
            set: Vec::new(),
        },
    )?)
}

pub(crate) fn stack(
    plan: &Plan,
    mode: Mode,
    opts: &BenchOptions,
    controller_cmd: Option<&[String]>,
) -> Result<run::RunOutcome, BenchError> {
    Ok(run::run(RunOptions {
        plan: plan.clone(),
        mode,
        csv: None,
        external: Vec::new(),
        runs_dir: opts.runs_dir.clone(),
        name: None,
        progress: false,
        realtime_setup: opts.realtime_setup,
        verbose: false,
        controller_cmd: controller_cmd.map(<[String]>::to_vec),
        live: None,
        log_compression: opts.log_compression,
    })?)
}

/// A real-time run of `plan` for `opts.realtime_s` with the timer floor
/// measured beside it (same window, CPU and priority); with
/// `controller_cmd`, that command is the controller node.
pub(crate) fn realtime_part(
    plan: &Plan,
    opts: &BenchOptions,
    controller_cmd: Option<&[String]>,
) -> Result<(RealtimeFigures, TimerFloor, Percentiles), BenchError> {
    let mut rt_plan = plan.clone();
    rt_plan.steps = (opts.realtime_s * plan.scenario.rate_hz).round() as u64;
    rt_plan.scenario.duration_s = opts.realtime_s;
    let placement = floor_placement(opts);
    // Start-up and shut-down take a few seconds at most; the probe keeps
    // running until the run is over, and only the run's window counts.
    let probe = FloorProbe::start(plan.scenario.rate_hz, opts.realtime_s + 60.0, &placement);
    let rt = stack(&rt_plan, Mode::Realtime, opts, controller_cmd);
    let (first_wake, cycles) = rt.as_ref().map_or((0, 0), |r| {
        (r.analysis.wall_window_ns.0, r.analysis.timing.cycles)
    });
    let floor = probe.finish(first_wake, cycles, plan.scenario.rate_hz);
    let rt = rt?;
    let t = &rt.analysis.timing;
    let figures = RealtimeFigures {
        cycles: t.cycles,
        deadline_misses: t.deadline_misses,
        late_wakeups: t.late_wakeups,
        period_jitter_us: t.period_jitter_us,
        round_trip_us: t.round_trip_us,
        logger_dropped: rt.analysis.contents.logger_dropped().unwrap_or(0),
    };
    Ok((figures, floor, t.controller_compute_us))
}

fn bench_arm(
    plan: &Plan,
    opts: &BenchOptions,
    round_trip_us: f64,
    progress: &mut impl FnMut(&str),
) -> Result<ArmBench, BenchError> {
    let sim_s = plan.steps as f64 * plan.dt();
    let (inprocess, costs) = in_process(plan, opts, progress)?;
    let mut lock_walls = Vec::new();
    let mut node_cpu = Vec::new();
    let mut rss = vec![(
        "in-process loop".to_string(),
        run::spawn::peak_rss_kb(std::process::id()).unwrap_or(0),
    )];
    for i in 0..opts.repeats {
        progress(&format!("{}: lockstep, run {}", plan.scenario.name, i + 1));
        let out = stack(plan, Mode::Lockstep, opts, None)?;
        lock_walls.push(out.wall_time_s);
        if i == 0 {
            node_cpu = (out.node_cpu_s.iter())
                .map(|(k, s)| (k.name().to_string(), *s))
                .collect();
            rss.extend(
                out.peak_rss_kb
                    .iter()
                    .map(|(k, kb)| (k.name().to_string(), *kb)),
            );
        }
    }
    let lockstep = median(lock_walls);
    progress(&format!(
        "{}: real time, {} s",
        plan.scenario.name, opts.realtime_s
    ));
    let (realtime, floor, _) = realtime_part(plan, opts, None)?;
    let lockstep_floor_s = plan.steps as f64 * round_trip_us * 1e-6 + inprocess;
    Ok(ArmBench {
        scenario: plan.scenario.name.clone(),
        dof: plan.robot.model.dof(),
        sim_s,
        inprocess_wall_s: inprocess,
        lockstep_wall_s: lockstep,
        lockstep_realtime_factor: sim_s / lockstep.max(1e-9),
        lockstep_to_inprocess_ratio: lockstep / inprocess.max(1e-9),
        lockstep_floor_s,
        lockstep_to_floor_ratio: lockstep / lockstep_floor_s.max(1e-9),
        controller_step_us: costs.controller_us.finish().p50,
        plant_step_us: costs.plant_us.finish().p50,
        realtime,
        timer_floor: floor,
        peak_rss_kb: rss,
        lockstep_node_cpu_s: node_cpu,
    })
}

/// Where the timer floor runs: the loop's CPU, one priority level above the
/// controller, so the loop never delays the floor's wake-ups (the floor may
/// delay the loop by the microsecond a wake-up takes, which counts against
/// the testbed).
fn floor_placement(opts: &BenchOptions) -> Placement {
    if opts.realtime_setup {
        let cpus = placement::cpu_count();
        let controller = placement::for_node(NodeKind::Controller, Mode::Realtime, cpus);
        Placement {
            fifo: controller.fifo.map(|p| p + 1),
            ..controller
        }
    } else {
        Placement::default()
    }
}

/// Median wall time of the in-process loop and the step costs of its first run.
fn in_process(
    plan: &Plan,
    opts: &BenchOptions,
    progress: &mut impl FnMut(&str),
) -> Result<(f64, StepCosts), BenchError> {
    let mut walls = Vec::new();
    let mut costs = StepCosts::default();
    for i in 0..opts.repeats {
        progress(&format!(
            "{}: in process, run {}",
            plan.scenario.name,
            i + 1
        ));
        let start = Instant::now();
        let keep = if i == 0 { Some(&mut costs) } else { None };
        sim::run_measured(plan, keep, |_| Ok(()))?;
        walls.push(start.elapsed().as_secs_f64());
    }
    Ok((median(walls), costs))
}

/// Runs the whole bench; `progress` hears what is being measured.
pub fn run(opts: &BenchOptions, mut progress: impl FnMut(&str)) -> Result<BenchReport, BenchError> {
    let paper = load(None, opts)?;
    let large = load(Some(&opts.large_arm), opts)?;
    progress(&format!(
        "iceoryx2 ping-pong, {} round trips x {}",
        paper.steps, opts.repeats
    ));
    let pingpong = crate::bench_pingpong::measure(paper.steps, opts.repeats, opts.realtime_setup)?;
    let rtt = pingpong.round_trip_us;
    let mut arms = vec![bench_arm(&paper, opts, rtt, &mut progress)?];
    arms.push(bench_arm(&large, opts, rtt, &mut progress)?);
    Ok(BenchReport {
        machine: machine(),
        repeats: opts.repeats,
        pingpong,
        realtime_setup: opts.realtime_setup,
        paper: arms[0].clone(),
        arms,
    })
}
