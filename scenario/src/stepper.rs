//! The one loop body of an in-process run: state k → the reference sample
//! due at its time → a command → the plant steps one period → state k+1.
//! `testbed sim` (`run_stack::sim`) and the Gym environment (`gym-env`) both
//! step through it, so a zero residual in the environment is `sim`, bit for
//! bit. The node processes of a lockstep run step the same three machines,
//! one per process, in the same order.

use crate::Plan;
use controller::ControllerMachine;
use plant_rapier::{PlantError, PlantMachine};
use trajectory::TrajectoryMachine;
use wire::{Command, ControllerDiagnostics, Header, JointState, ReferenceSample};

/// The plant and the reference of one run, at step k.
#[derive(Debug)]
pub struct Stepper {
    plant: PlantMachine,
    reference: TrajectoryMachine,
    /// State k as the plant published it.
    state: JointState,
    /// The reference sample a controller uses at state k's time.
    r: ReferenceSample,
    k: u64,
}

impl Stepper {
    /// The run of `plan` at its first state.
    pub fn new(plan: &Plan) -> Result<Self, PlantError> {
        let mut plant = plan.plant_config().machine()?;
        let mut reference = plan.trajectory_config().machine();
        let state = plant.state(0, 0);
        let r = reference_at(&mut reference, &state);
        Ok(Self {
            plant,
            reference,
            state,
            r,
            k: 0,
        })
    }

    /// State k.
    pub fn state(&self) -> &JointState {
        &self.state
    }

    /// The reference sample due at state k's time.
    pub fn reference(&self) -> &ReferenceSample {
        &self.r
    }

    /// The step the next command acts at (0 at the start).
    pub fn k(&self) -> u64 {
        self.k
    }

    /// Steps in the run.
    pub fn steps(&self) -> u64 {
        self.plant.steps()
    }

    /// Controlled joints.
    pub fn dof(&self) -> usize {
        self.plant.dof()
    }

    /// `law`'s command and diagnostics at state k.
    pub fn command(&self, law: &mut ControllerMachine) -> (Command, ControllerDiagnostics) {
        law.step(&self.state, Some(&self.r))
    }

    /// A command of zero torque stamped for state k (what an action adds
    /// to when there is no law under it).
    pub fn zero_command(&self) -> Command {
        Command {
            header: Header {
                seq: self.state.header.seq,
                t_ns: self.state.header.t_ns,
                wall_ns: 0,
            },
            dof: self.plant.dof() as u32,
            fault: 0,
            tau: [0.0; wire::MAX_DOF],
            state_wall_ns: 0,
            compute_ns: 0,
            started_wall_ns: 0,
            reference_t_ns: self.r.header.t_ns,
            stale_references: 0,
        }
    }

    /// The plant steps one period with `command`; state k+1 and its
    /// reference sample are read even when the step failed (the caller
    /// decides whether the run goes on), and the failure is returned.
    pub fn advance(&mut self, command: &Command) -> Result<(), PlantError> {
        let stepped = self.plant.step(Some(command));
        self.k += 1;
        self.state = self.plant.state(self.k, 0);
        self.r = reference_at(&mut self.reference, &self.state);
        stepped
    }
}

/// The reference sample a controller uses at `state`'s time.
fn reference_at(reference: &mut TrajectoryMachine, state: &JointState) -> ReferenceSample {
    reference.sample(reference.index_at(state.header.t_ns), 0)
}
