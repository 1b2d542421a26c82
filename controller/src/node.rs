//! The controller process: the [`ControllerMachine`] behind the bus. It
//! wakes on each joint state, takes the reference sample for the state's
//! time from the trajectory process ([`ReferenceWindow`]), and publishes the command and the
//! diagnostics of that step.

use std::time::{Duration, Instant};

use bus::{NodeError, NodeLink, ReferenceWindow, monotonic_ns};
use serde::{Deserialize, Serialize};
use wire::{Command, ControllerDiagnostics, JointState, Mode, ReferenceSample, STATE_FINAL};

use arm_model::{ArmModel, Locks};

use crate::{ControllerError, ControllerMachine, ControllerMachineConfig, ControllerParams};

/// What the launcher hands the controller node: gains and sizes, and the
/// arm's URDF only for a model-based law.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerNodeConfig {
    /// The law's parameters.
    pub params: ControllerParams,
    /// Controlled joints.
    pub dof: usize,
    /// Control period, ns.
    pub period_ns: u64,
    /// Reference sample period, ns: which sample is due at a state's time
    /// (0 or absent: the control period).
    #[serde(default)]
    pub reference_period_ns: u64,
    /// The arm's model, for `pd-gravity` and `ctc` (None for the others).
    #[serde(default)]
    pub model: Option<NodeModel>,
    /// An external controller's own parameters (its declared defaults with
    /// the scenario's `[external]` table over them); the testbed's own
    /// controller takes none.
    #[serde(default, skip_serializing_if = "serde_json::Map::is_empty")]
    pub own_params: serde_json::Map<String, serde_json::Value>,
    /// Its own diagnostics, as `name:shape` pairs ([`wire::OwnLayout`]):
    /// the order it publishes their values in.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub own_diagnostics: String,
    /// The run's scenario, by its file's stem ("paper_randomised"; empty:
    /// not said): a policy trained on another is warned about.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub scenario: String,
}

/// The URDF a model-based law evaluates, with the run's locked joints.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodeModel {
    /// The URDF text.
    pub urdf: String,
    /// Joint name → locked position.
    pub lock: Locks,
}

impl ControllerNodeConfig {
    /// The reference period, ns (the control period when unset).
    pub fn reference_period(&self) -> u64 {
        match self.reference_period_ns {
            0 => self.period_ns,
            r => r,
        }
    }

    /// The step machine this configuration describes (a config written by
    /// hand is checked like a scenario: sizes first).
    pub fn machine(&self) -> Result<ControllerMachine, ControllerError> {
        let model = match &self.model {
            Some(m) => Some(
                ArmModel::from_urdf_str_locked(&m.urdf, &m.lock).map_err(|e| {
                    ControllerError::InvalidParameter {
                        key: "model.urdf".into(),
                        value: "the run's URDF".into(),
                        need: format!("a URDF the arm model reads ({e})"),
                    }
                })?,
            ),
            None => None,
        };
        ControllerMachineConfig {
            params: self.params.clone(),
            dof: self.dof,
            period_ns: self.period_ns,
            model,
        }
        .machine()
    }
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

impl From<bus::BusError> for ControllerNodeError {
    fn from(e: bus::BusError) -> Self {
        Self::Node(e.into())
    }
}

/// Runs the controller node to the end of the run.
pub fn run(
    link: &mut NodeLink,
    config: &ControllerNodeConfig,
    mode: Mode,
) -> Result<(), ControllerNodeError> {
    let mut m = config.machine()?;
    let stepped = serve(link, mode, config.reference_period(), |s, r| {
        let (cmd, diag) = m.step(s, r);
        (cmd, diag, None::<std::convert::Infallible>)
    });
    match stepped {
        Ok(()) => Ok(()),
        Err(ServeError::Node(e)) => Err(e.into()),
        Err(ServeError::Step(never)) => match never {},
    }
}

/// Why [`serve`] stopped before the run's end.
#[derive(Debug, thiserror::Error)]
pub enum ServeError<E> {
    /// The node protocol or the bus.
    #[error(transparent)]
    Node(#[from] NodeError),
    /// The step said the run cannot go on (its command went out first).
    #[error("{0}")]
    Step(E),
}

impl<E> From<bus::BusError> for ServeError<E> {
    fn from(e: bus::BusError) -> Self {
        Self::Node(e.into())
    }
}

/// The controller side of the node protocol, for any law: READY, then on
/// each joint state the reference sample due at its time, `step`, and the
/// command and diagnostics published with their timing stamps and the
/// stale-reference count; the launcher is checked in with every 256 states
/// and on a quiet 100 ms; DONE at the final state. A step that returns an
/// error has its command published, then ends the run with it (a policy
/// whose network gave NaN: zero torque with the fault flag, then the
/// reason). `testbed node controller` and `testbed-policy` both serve
/// through it.
pub fn serve<E>(
    link: &mut NodeLink,
    mode: Mode,
    reference_period_ns: u64,
    mut step: impl FnMut(
        &JointState,
        Option<&ReferenceSample>,
    ) -> (Command, ControllerDiagnostics, Option<E>),
) -> Result<(), ServeError<E>> {
    let states = link.bus.subscriber::<JointState>()?;
    let commands = link.bus.publisher::<Command>(mode.delivery())?;
    let diagnostics = link
        .bus
        .publisher::<ControllerDiagnostics>(mode.delivery())?;
    let mut reference = ReferenceWindow::new(link, mode, reference_period_ns)?;
    link.ready_and_wait_for_start()?;

    let mut handled = 0u64;
    loop {
        let mut finished = false;
        while let Some(s) = states.receive()? {
            if s.flags & STATE_FINAL != 0 {
                finished = true;
                continue;
            }
            let started_wall_ns = monotonic_ns();
            let started = Instant::now();
            let r = reference.take(link, s.header.t_ns)?;
            let (mut cmd, mut diag, failed) = step(&s, r.as_ref());
            let compute_ns = started.elapsed().as_nanos() as u64;
            let wall_ns = monotonic_ns();
            cmd.header.wall_ns = wall_ns;
            cmd.compute_ns = compute_ns;
            cmd.started_wall_ns = started_wall_ns;
            cmd.stale_references = reference.stale_count();
            diag.header.wall_ns = wall_ns;
            diag.compute_ns = compute_ns;
            commands.send(cmd)?;
            diagnostics.send(diag)?;
            if let Some(e) = failed {
                return Err(ServeError::Step(e));
            }
            handled += 1;
            // Checked every 256 states (and on a timeout), not on every
            // wake-up; here, so that a loop that always finds the next
            // state waiting still checks in (and sends its heartbeat).
            if handled.is_multiple_of(256) {
                link.check()?;
            }
        }
        if finished {
            break;
        }
        // The wait takes every pending wake-up with it: no drain after it.
        if !states.wait_event(Duration::from_millis(100))? {
            link.check()?;
        }
    }
    Ok(link.done_and_wait_for_stop(handled)?)
}
