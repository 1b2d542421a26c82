//! The trajectory process: the [`TrajectoryMachine`] behind the bus,
//! publishing q_d, q̇_d, q̈_d, k_c and k̇_c.
//!
//! In real time it runs on its own absolute-deadline timer from the epoch
//! the launcher gives, publishing each sample a horizon ahead of its time
//! (`reference.horizon_s`), so the sample for t_k is there when state k
//! arrives even when the machine delays this process. In lockstep it runs up to [`AHEAD`]
//! samples ahead of the plant's newest state: the controller waits for the
//! sample it needs, which is almost always there already.

use std::time::Duration;

use bus::clock;
use bus::{NodeError, NodeLink, monotonic_ns};
use serde::{Deserialize, Serialize};
use wire::{JointState, Mode, ReferenceSample};

use crate::{
    EnvelopeConfig, Reference, ReferenceConfig, TrajectoryError, TrajectoryMachine,
    TrajectoryMachineConfig,
};

/// Samples the lockstep trajectory may publish beyond the plant's newest
/// state: well inside a subscriber's buffer, so it never waits on a reader.
pub const AHEAD: u64 = 1024;

/// What the launcher hands the trajectory node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrajectoryNodeConfig {
    /// q_d(t).
    pub reference: ReferenceConfig,
    /// k_c(t).
    pub envelope: EnvelopeConfig,
    /// Joint limits, for an envelope taken from them.
    pub limits: Vec<Option<(f64, f64)>>,
    /// Joint names, for messages.
    pub joint_names: Vec<String>,
    /// Control period, ns.
    pub period_ns: u64,
    /// Reference period, ns.
    pub reference_period_ns: u64,
    /// Real time: each sample goes out this long before its time, ns.
    pub horizon_ns: u64,
    /// Control steps in the run.
    pub steps: u64,
}

impl TrajectoryNodeConfig {
    /// The machine this config describes.
    pub fn machine(&self) -> Result<TrajectoryMachine, TrajectoryError> {
        let r = Reference::with_limits(
            &self.reference,
            &self.envelope,
            &self.limits,
            &self.joint_names,
        )?;
        Ok(TrajectoryMachineConfig {
            reference: r,
            reference_period_ns: self.reference_period_ns,
        }
        .machine())
    }
}

/// Why the trajectory node stopped.
#[derive(Debug, thiserror::Error)]
pub enum TrajectoryNodeError {
    /// The node protocol or the bus.
    #[error(transparent)]
    Node(#[from] NodeError),
    /// The reference is unusable.
    #[error("trajectory: {0}")]
    Trajectory(#[from] TrajectoryError),
}

impl From<bus::BusError> for TrajectoryNodeError {
    fn from(e: bus::BusError) -> Self {
        Self::Node(e.into())
    }
}

/// Runs the trajectory node to the end of the run.
pub fn run(
    link: &mut NodeLink,
    config: &TrajectoryNodeConfig,
    mode: Mode,
) -> Result<(), TrajectoryNodeError> {
    let mut m = config.machine()?;
    let out = link.bus.publisher::<ReferenceSample>(mode.delivery())?;
    let states = match mode {
        Mode::Lockstep => Some(link.bus.polling_subscriber::<JointState>()?),
        Mode::Realtime => None,
    };
    let epoch = link.ready_and_wait_for_start()?;
    // Samples for t_0 … the end of the run.
    let last = config.steps * config.period_ns / m.period_ns();
    let publish = |m: &mut TrajectoryMachine, j: u64| out.send(m.sample(j, monotonic_ns()));
    match states {
        None => {
            clock::tighten_timer_slack();
            for j in 0..=last {
                // Each sample goes out a horizon before its time (the
                // first ones at once, before step 0).
                clock::sleep_until((epoch + j * m.period_ns()).saturating_sub(config.horizon_ns));
                publish(&mut m, j)?;
                if j % 32 == 0 {
                    link.check()?;
                }
            }
        }
        Some(states) => {
            let (mut next, mut plant_t_ns) = (0u64, 0u64);
            loop {
                let horizon = m.index_at(plant_t_ns) + AHEAD;
                while next <= last.min(horizon) {
                    publish(&mut m, next)?;
                    next += 1;
                }
                if next > last {
                    break;
                }
                link.bus.wait(Duration::from_millis(2))?;
                link.check()?;
                while let Some(s) = states.receive()? {
                    plant_t_ns = plant_t_ns.max(s.header.t_ns);
                }
                states.drain_events()?;
            }
        }
    }
    Ok(link.done_and_wait_for_stop(last + 1)?)
}
