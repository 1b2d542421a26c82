//! `testbed bench`: how fast and how steady the testbed is on this machine.
//!
//! For the paper scenario and the largest shipped arm it measures the
//! in-process loop, the full stack in lockstep with the logger, and the full
//! stack in real time; and, in the same run, the floor the machine sets: a
//! bare absolute-deadline sleep loop with no IPC and no work. On a shared VM
//! the host, not the code, sets the timing tail, so the testbed's figures
//! are reported beside that floor.

use std::path::{Path, PathBuf};
use std::time::Instant;

use scenario::{Overrides, Plan};
use serde::Serialize;

use crate::clock;
use crate::closed_loop::{self, StepCosts};
use crate::mode::Mode;
use crate::node::placement::{self, Placement};
use crate::run::timing::{Percentiles, TimingStats};
use crate::run::{self, RunError, RunOptions};
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
}

/// Why a bench failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A scenario could not be loaded.
    #[error(transparent)]
    Scenario(#[from] scenario::ScenarioError),
    /// The in-process loop failed.
    #[error(transparent)]
    Loop(#[from] closed_loop::LoopError),
    /// A multi-process run failed.
    #[error(transparent)]
    Run(#[from] RunError),
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
    /// Cycles.
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
    /// Controller step (median), µs.
    pub controller_step_us: f64,
    /// Plant step (median, all substeps), µs.
    pub plant_step_us: f64,
    /// Real time at the scenario rate.
    pub realtime: RealtimeFigures,
    /// Peak resident memory, kB: the in-process loop (this process) and each node.
    pub peak_rss_kb: Vec<(String, u64)>,
}

/// The whole bench. The top-level figures are the paper scenario's.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Where it ran.
    pub machine: Machine,
    /// Repeats per part.
    pub repeats: usize,
    /// Whether the nodes were pinned and, in real time, ran under SCHED_FIFO.
    pub realtime_setup: bool,
    /// The paper scenario's figures, at the top level of the JSON.
    #[serde(flatten)]
    pub paper: ArmBench,
    /// The bare sleep loop, same length, same bench run.
    pub timer_floor: TimerFloor,
    /// Every arm's figures.
    pub arms: Vec<ArmBench>,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

fn median_us(v: &[u64]) -> f64 {
    median(v.iter().map(|x| *x as f64 / 1e3).collect())
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
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        kernel: std::fs::read_to_string("/proc/sys/kernel/osrelease")
            .map_or_else(|_| "unknown".into(), |s| s.trim().to_string()),
    }
}

/// A bare absolute-deadline loop at `rate_hz` for `seconds`, in a thread
/// of its own placed as `placement` says.
pub fn timer_floor(rate_hz: f64, seconds: f64, placement: &Placement) -> TimerFloor {
    let placement = placement.clone();
    std::thread::scope(|s| {
        s.spawn(move || {
            let refused = placement.apply();
            TimerFloor {
                placement_refused: refused,
                ..sleep_loop(rate_hz, seconds)
            }
        })
        .join()
        .unwrap_or_else(|_| sleep_loop(rate_hz, seconds))
    })
}

fn sleep_loop(rate_hz: f64, seconds: f64) -> TimerFloor {
    clock::tighten_timer_slack();
    let period = (1e9 / rate_hz).round() as u64;
    let cycles = (seconds * rate_hz).round() as u64;
    let epoch = clock::monotonic_ns() + period;
    let mut stats = TimingStats::new(period);
    let mut last = epoch;
    let mut misses = 0;
    for k in 0..cycles {
        let deadline = epoch + k * period;
        clock::sleep_until(deadline);
        let wake = clock::monotonic_ns();
        if wake >= deadline + period {
            misses += 1;
        }
        stats.add(&wire::Timing {
            period_ns: if k == 0 { 0 } else { (wake - last) as i64 },
            round_trip_ns: -1,
            controller_compute_ns: -1,
            ..wire::Timing::default()
        });
        last = wake;
    }
    let t = stats.finish(Mode::Realtime, rate_hz);
    TimerFloor {
        cycles,
        deadline_misses: misses,
        period_jitter_us: t.period_jitter_us,
        placement_refused: Vec::new(),
    }
}

fn load(robot: Option<&Path>, opts: &BenchOptions) -> Result<Plan, BenchError> {
    Ok(scenario::load(
        None,
        &Overrides {
            duration_s: opts.duration_s,
            rate_hz: None,
            robot: robot.map(Path::to_path_buf),
        },
    )?)
}

fn stack(plan: &Plan, mode: Mode, opts: &BenchOptions) -> Result<run::RunOutcome, BenchError> {
    Ok(run::run(RunOptions {
        plan: plan.clone(),
        mode,
        csv: None,
        external: Vec::new(),
        runs_dir: opts.runs_dir.clone(),
        progress: false,
        realtime_setup: opts.realtime_setup,
    })?)
}

fn bench_arm(
    plan: &Plan,
    opts: &BenchOptions,
    progress: &mut impl FnMut(&str),
) -> Result<ArmBench, BenchError> {
    let sim_s = plan.steps as f64 * plan.dt();
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
        closed_loop::run_measured(plan, keep, |_| Ok(()))?;
        walls.push(start.elapsed().as_secs_f64());
    }
    let inprocess = median(walls);
    let mut lock_walls = Vec::new();
    let mut rss = vec![(
        "in-process loop".to_string(),
        run::spawn::peak_rss_kb(std::process::id()).unwrap_or(0),
    )];
    for i in 0..opts.repeats {
        progress(&format!("{}: lockstep, run {}", plan.scenario.name, i + 1));
        let out = stack(plan, Mode::Lockstep, opts)?;
        lock_walls.push(out.wall_time_s);
        if i == 0 {
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
    let mut rt_plan = plan.clone();
    rt_plan.steps = (opts.realtime_s * plan.scenario.rate_hz).round() as u64;
    rt_plan.scenario.duration_s = opts.realtime_s;
    let rt = stack(&rt_plan, Mode::Realtime, opts)?;
    let t = &rt.analysis.timing;
    let dropped = rt.analysis.contents.logger_dropped().unwrap_or(0);
    Ok(ArmBench {
        scenario: plan.scenario.name.clone(),
        dof: plan.robot.model.dof(),
        sim_s,
        inprocess_wall_s: inprocess,
        lockstep_wall_s: lockstep,
        lockstep_realtime_factor: sim_s / lockstep.max(1e-9),
        lockstep_to_inprocess_ratio: lockstep / inprocess.max(1e-9),
        controller_step_us: median_us(&costs.controller_ns),
        plant_step_us: median_us(&costs.plant_ns),
        realtime: RealtimeFigures {
            cycles: t.cycles,
            deadline_misses: t.deadline_misses,
            period_jitter_us: t.period_jitter_us,
            round_trip_us: t.round_trip_us,
            logger_dropped: dropped,
        },
        peak_rss_kb: rss,
    })
}

/// Runs the whole bench; `progress` hears what is being measured.
pub fn run(opts: &BenchOptions, mut progress: impl FnMut(&str)) -> Result<BenchReport, BenchError> {
    let paper = load(None, opts)?;
    let large = load(Some(&opts.large_arm), opts)?;
    let mut arms = vec![bench_arm(&paper, opts, &mut progress)?];
    arms.push(bench_arm(&large, opts, &mut progress)?);
    progress(&format!(
        "timer floor: bare sleep loop, {} s",
        opts.realtime_s
    ));
    let placement = if opts.realtime_setup {
        let cpus = std::thread::available_parallelism().map_or(1, usize::from);
        placement::for_node(NodeKind::Plant, Mode::Realtime, cpus)
    } else {
        Placement::default()
    };
    let floor = timer_floor(paper.scenario.rate_hz, opts.realtime_s, &placement);
    Ok(BenchReport {
        machine: machine(),
        repeats: opts.repeats,
        realtime_setup: opts.realtime_setup,
        paper: arms[0].clone(),
        timer_floor: floor,
        arms,
    })
}
