//! The controller process: the [`ControllerMachine`] behind the bus. It
//! wakes on each joint state, takes the reference sample for the state's
//! time from the trajectory process, and publishes the command and the
//! diagnostics of that step.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};
use wire::{
    Command, ControllerDiagnostics, JointState, Mode, NodeError, NodeLink, ReferenceSample,
    STATE_FINAL, Topic, TopicSubscriber, monotonic_ns,
};

use crate::{ControllerError, ControllerMachine, ControllerParams};

/// What the launcher hands the controller node: only gains and sizes,
/// never the arm's model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerNodeConfig {
    /// The law's parameters.
    pub params: ControllerParams,
    /// Controlled joints.
    pub dof: usize,
    /// Control period, ns.
    pub period_ns: u64,
}

/// Why the controller node stopped.
#[derive(Debug, thiserror::Error)]
pub enum ControllerNodeError {
    /// The node protocol or the bus.
    #[error(transparent)]
    Node(#[from] NodeError),
    /// The controller could not be built.
    #[error("controller: {0}")]
    Controller(#[from] ControllerError),
}

impl From<wire::WireError> for ControllerNodeError {
    fn from(e: wire::WireError) -> Self {
        Self::Node(e.into())
    }
}

/// The reference samples the trajectory process publishes: the newest one
/// not later than the state is used, in every mode.
///
/// Lockstep: the controller waits until the sample for the state's time is
/// final (one at or after it has arrived; the trajectory runs ahead of the
/// plant), so the run is deterministic whoever publishes the reference.
/// Real time: what has arrived by then; none yet is a fault.
struct RefSource {
    sub: TopicSubscriber<ReferenceSample>,
    recent: VecDeque<ReferenceSample>,
    wait_for_final: bool,
}

impl RefSource {
    /// The sample for sim time `t_ns`, if there is one.
    fn take(
        &mut self,
        link: &mut NodeLink,
        t_ns: u64,
    ) -> Result<Option<ReferenceSample>, NodeError> {
        loop {
            while let Some(r) = self.sub.receive()? {
                arrive(&mut self.recent, r);
            }
            let settled = self.recent.back().is_some_and(|r| r.header.t_ns >= t_ns);
            if settled || !self.wait_for_final {
                return Ok(pick_reference(&mut self.recent, t_ns));
            }
            // Only at the start, or when a replacement trajectory is slow.
            link.bus.wait(Duration::from_millis(1))?;
            link.check()?;
        }
    }
}

/// Keeps `recent` in time order: samples from one publisher come in order,
/// so this is a push at the back; a late one is put in its place.
fn arrive(recent: &mut VecDeque<ReferenceSample>, r: ReferenceSample) {
    if recent.back().is_none_or(|b| b.header.t_ns <= r.header.t_ns) {
        recent.push_back(r);
    } else {
        let i = recent.partition_point(|x| x.header.t_ns <= r.header.t_ns);
        recent.insert(i, r);
    }
}

/// The newest sample at or before `t_ns`, dropping the older ones. Samples
/// after `t_ns` are kept: when the plant runs late, the trajectory's timer is
/// ahead of it and those samples are needed for the next states. O(1) per
/// state (the lockstep trajectory runs a thousand samples ahead).
fn pick_reference(recent: &mut VecDeque<ReferenceSample>, t_ns: u64) -> Option<ReferenceSample> {
    while recent.get(1).is_some_and(|r| r.header.t_ns <= t_ns) {
        recent.pop_front();
    }
    recent.front().filter(|r| r.header.t_ns <= t_ns).copied()
}

/// Runs the controller node to the end of the run.
pub fn run(
    link: &mut NodeLink,
    config: &ControllerNodeConfig,
    mode: Mode,
) -> Result<(), ControllerNodeError> {
    let mut m = ControllerMachine::new(config.params.clone(), config.dof, config.period_ns)?;
    let states = link.bus.subscriber::<JointState>(Topic::JointState)?;
    let commands = link
        .bus
        .publisher::<Command>(Topic::Command, mode.delivery())?;
    let diagnostics = link
        .bus
        .publisher::<ControllerDiagnostics>(Topic::Diagnostics, mode.delivery())?;
    let mut reference = RefSource {
        sub: link.bus.subscriber(Topic::Reference)?,
        recent: VecDeque::with_capacity(2048),
        wait_for_final: mode == Mode::Lockstep,
    };
    link.ready_and_wait_for_start()?;

    let mut handled = 0u64;
    loop {
        let mut finished = false;
        while let Some(s) = states.receive()? {
            if s.flags & STATE_FINAL != 0 {
                finished = true;
                continue;
            }
            let started = Instant::now();
            let r = reference.take(link, s.header.t_ns)?;
            let (mut cmd, mut diag) = m.step(&s, r.as_ref());
            let compute_ns = started.elapsed().as_nanos() as u64;
            let wall_ns = monotonic_ns();
            cmd.header.wall_ns = wall_ns;
            cmd.compute_ns = compute_ns;
            diag.header.wall_ns = wall_ns;
            diag.compute_ns = compute_ns;
            commands.send(cmd)?;
            diagnostics.send(diag)?;
            handled += 1;
        }
        if finished {
            break;
        }
        // Checked on a timeout and every 256 states, not on every wake-up.
        if !states.wait_event(Duration::from_millis(100))? || handled.is_multiple_of(256) {
            link.check()?;
        }
        states.drain_events()?;
    }
    Ok(link.done_and_wait_for_stop(handled)?)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn sample(t_ns: u64) -> ReferenceSample {
        ReferenceSample {
            header: wire::Header {
                seq: t_ns,
                t_ns,
                wall_ns: 0,
            },
            dof: 1,
            kc: [1.0; wire::MAX_DOF],
            ..ReferenceSample::default()
        }
    }

    fn arrived(ts: &[u64]) -> VecDeque<ReferenceSample> {
        let mut recent = VecDeque::new();
        for &t in ts {
            arrive(&mut recent, sample(t));
        }
        recent
    }

    #[test]
    fn newest_sample_not_after_the_state_wins() {
        let mut recent = arrived(&[3, 1, 2, 5]);
        assert_eq!(pick_reference(&mut recent, 4).unwrap().header.t_ns, 3);
        assert_eq!(
            recent.iter().map(|r| r.header.t_ns).collect::<Vec<_>>(),
            [3, 5]
        );
        assert!(pick_reference(&mut arrived(&[7]), 6).is_none());
    }

    /// Regression: with the plant 20 periods behind the trajectory, the
    /// controller once kept only the newest 8 samples, all later than the
    /// state, and faulted with no reference.
    #[test]
    fn reference_is_found_when_the_plant_runs_late() {
        let mut recent = arrived(&(0..40).collect::<Vec<_>>());
        for k in 0..40 {
            assert_eq!(pick_reference(&mut recent, k).unwrap().header.t_ns, k);
        }
    }
}
