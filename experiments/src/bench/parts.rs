//! The parts a bench is made of: the plan it loads, a run of the stack,
//! and a real-time run with the timer floor measured beside it.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use analysis::timing::{Percentiles, TimingStats};
use bus::clock;
use run_stack::mode::Mode;
use run_stack::node::placement::{self, Placement};
use run_stack::run::{self, RunOptions};
use scenario::{Overrides, Plan};
use wire::NodeKind;

use crate::bench::types::{BenchError, BenchOptions, RealtimeFigures, TimerFloor};

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
