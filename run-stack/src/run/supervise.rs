//! Watching a started run: wait for every node's READY, send START,
//! follow the plant's progress until every producer is DONE, and fail at
//! once, by name, on a node that exits, falls silent, stalls or does not
//! finish.

use std::time::{Duration, Instant};

use bus::{Bus, BusError, monotonic_ns};
use wire::{CONTROL_START, Control, NodeKind, NodeStatus};

use super::nodes::NodeStates;
use super::spawn::{Children, describe};
use super::{NODES, RunError, RunOptions, control_msg};
use crate::mode::Mode;

/// The nodes whose DONE ends a run; the logger then finishes the file.
const PRODUCERS: [NodeKind; 3] = [NodeKind::Plant, NodeKind::Trajectory, NodeKind::Controller];

/// How long nodes may take to connect.
const START_TIMEOUT: Duration = Duration::from_secs(30);
/// How long a node started by hand (`--external`) may take to connect.
const EXTERNAL_START_TIMEOUT: Duration = Duration::from_secs(300);
/// A run whose row count does not move for this long is declared stuck.
const STALL_TIMEOUT: Duration = Duration::from_secs(20);
/// Once the plant has made its last step, the other producers must finish
/// within this: one that does not is stopped, spinning or deadlocked.
const FINISH_TIMEOUT: Duration = Duration::from_secs(5);
/// How often the launcher wakes to drain topics and check its children.
const TICK: Duration = Duration::from_millis(10);

/// Waits for READY, sends START, follows the plant's progress until every
/// producer is DONE. Returns the wall time of the run proper.
pub(super) fn supervise(
    opts: &RunOptions,
    bus: &Bus,
    status: &bus::TopicSubscriber<NodeStatus>,
    control: &bus::TopicPublisher<Control>,
    children: &mut Children,
) -> Result<f64, RunError> {
    let plan = &opts.plan;
    let mut nodes = wait_for_ready(opts, bus, status, children)?;

    // Step 0 a little in the future, so every node is waiting for it.
    // On a whole multiple of the period: the plant's deadlines then fall on
    // the same CLOCK_MONOTONIC grid as any other loop at that rate (the
    // bench's timer floor runs on it too).
    let period = opts.plan.period_ns;
    let epoch = (monotonic_ns() + 20_000_000).div_ceil(period) * period;
    let mut start = control_msg(CONTROL_START, epoch);
    start.code = opts.mode.code();
    control.send(start)?;
    let started = Instant::now();
    let bar = progress_bar(opts);
    let mut last_step = 0;
    let mut last_change = Instant::now();
    let mut wall = None;
    while PRODUCERS.iter().any(|k| !nodes.done.contains(k)) {
        tick(bus)?;
        nodes.read(status)?;
        if nodes.done.contains(&NodeKind::Plant) && wall.is_none() {
            // A run cut short is never a finished one.
            if nodes.plant_step < plan.steps {
                return Err(RunError::NodeFailed {
                    node: NodeKind::Plant.name(),
                    how: format!(
                        "reported DONE after {} of {} steps",
                        nodes.plant_step, plan.steps
                    ),
                    stderr: String::new(),
                });
            }
            wall = Some(started.elapsed().as_secs_f64());
        }
        if let Some(w) = wall
            && started.elapsed().as_secs_f64() - w > FINISH_TIMEOUT.as_secs_f64()
        {
            return Err(RunError::NotFinished {
                nodes: PRODUCERS
                    .iter()
                    .filter(|k| !nodes.done.contains(k))
                    .map(|k| k.name())
                    .collect(),
                secs: FINISH_TIMEOUT.as_secs(),
            });
        }
        check_children(children)?;
        if let Some(node) = nodes.silent(wire::SILENT_AFTER) {
            return Err(RunError::Silent {
                node: node.name(),
                secs: wire::SILENT_AFTER.as_secs(),
                step: nodes.plant_step,
                steps: plan.steps,
            });
        }
        if let Some(b) = &bar {
            b.set_position(nodes.plant_step);
        }
        if nodes.plant_step != last_step || nodes.done.contains(&NodeKind::Plant) {
            last_step = nodes.plant_step;
            last_change = Instant::now();
        } else if last_change.elapsed() > STALL_TIMEOUT {
            return Err(RunError::Stalled {
                step: last_step,
                steps: plan.steps,
                secs: STALL_TIMEOUT.as_secs(),
            });
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    Ok(wall.unwrap_or_else(|| started.elapsed().as_secs_f64()))
}

/// Waits until every node has reported READY (or fails: a node exited,
/// or the start-up limit passed).
fn wait_for_ready(
    opts: &RunOptions,
    bus: &Bus,
    status: &bus::TopicSubscriber<NodeStatus>,
    children: &mut Children,
) -> Result<NodeStates, RunError> {
    let mut nodes = NodeStates::with_pids(children.pids());
    let limit = if opts.external.is_empty() {
        START_TIMEOUT
    } else {
        EXTERNAL_START_TIMEOUT
    };
    let start_wait = Instant::now();
    while NODES.iter().any(|k| !nodes.ready.contains(k)) {
        tick(bus)?;
        nodes.read(status)?;
        check_children(children)?;
        if start_wait.elapsed() > limit {
            return Err(RunError::StartTimeout {
                missing: NODES
                    .iter()
                    .filter(|k| !nodes.ready.contains(k))
                    .map(|k| k.name())
                    .collect(),
                secs: limit.as_secs(),
            });
        }
    }
    Ok(nodes)
}

/// Sleeps one tick; a SIGINT or SIGTERM turns into `Interrupted`.
fn tick(bus: &Bus) -> Result<(), RunError> {
    bus.wait(TICK).map_err(|e| match e {
        BusError::Terminated => RunError::Interrupted,
        other => RunError::Wire(other),
    })
}

/// Any child that exits before the run is over has failed.
fn check_children(children: &mut Children) -> Result<(), RunError> {
    children.watch();
    match children.first_exited() {
        Some((kind, status, stderr)) => Err(RunError::NodeFailed {
            node: kind.name(),
            how: describe(status),
            stderr,
        }),
        None => Ok(()),
    }
}

fn progress_bar(opts: &RunOptions) -> Option<indicatif::ProgressBar> {
    if !opts.progress || opts.mode != Mode::Realtime {
        return None;
    }
    let bar = indicatif::ProgressBar::new(opts.plan.steps);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{spinner} real time {elapsed_precise} [{bar:40}] step {pos}/{len}",
    ) {
        bar.set_style(style);
    }
    Some(bar)
}
