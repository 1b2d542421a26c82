//! `testbed bench`: how fast and how steady the testbed is on this machine.
//!
//! For the paper scenario and the largest shipped arm it measures the
//! in-process loop, the full stack in lockstep with the logger, and the full
//! stack in real time; and, beside each real-time run (same window, same
//! CPU, same priority), the floor the machine sets: a bare absolute-deadline
//! sleep loop with no IPC and no work. On a shared VM the host, not the
//! code, sets the timing tail, and it changes from minute to minute, so the
//! testbed's figures are reported beside a floor measured at the same time.

use std::time::Instant;

use scenario::Plan;

use run_stack::mode::Mode;
use run_stack::run::{self};
use run_stack::sim::{self, StepCosts};

pub mod controller;
pub mod parts;
pub mod peer;
pub mod pingpong;
pub mod table;
pub mod types;

use parts::{load, realtime_part, stack};
pub use types::*;

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
    let pingpong = crate::bench::pingpong::measure(paper.steps, opts.repeats, opts.realtime_setup)?;
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
