//! `testbed sim`: the run in one process. The plant, trajectory and
//! controller step machines are called in order with the same messages the
//! nodes exchange, and the step records come from the same assembler that
//! reads a multi-process run's log: so lockstep reproduces this bit for bit.

use controller::ControllerError;
use plant_rapier::PlantError;
use scenario::Plan;
use trajectory::TrajectoryMachine;

use analysis::assemble::RecordAssembler;
use analysis::record::StepRecord;
use analysis::timing::Quantiles;

/// Why the loop stopped early.
#[derive(Debug, thiserror::Error)]
pub enum LoopError {
    /// The plant could not be built or stepped.
    #[error("plant ({robot}): {cause}")]
    Plant {
        /// The robot's label.
        robot: String,
        /// The cause.
        cause: PlantError,
    },
    /// The controller could not be built.
    #[error("controller: {0}")]
    Controller(#[from] ControllerError),
    /// The step consumer failed (e.g. the CSV file could not be written).
    #[error("writing step {step}: {cause}")]
    Sink {
        /// The step being written.
        step: u64,
        /// The cause.
        cause: std::io::Error,
    },
}

/// Wall time of the plant and controller steps, µs, in bounded memory
/// (exact percentiles for a million steps, 0.1 % past that).
#[derive(Debug, Default, Clone)]
pub struct StepCosts {
    /// The plant steps.
    pub plant_us: Quantiles,
    /// The controller steps.
    pub controller_us: Quantiles,
}

/// Runs `plan` to the end, handing every step to `on_step`.
pub fn run(
    plan: &Plan,
    on_step: impl FnMut(&StepRecord<'_>) -> std::io::Result<()>,
) -> Result<(), LoopError> {
    run_measured(plan, None, on_step)
}

/// [`run`], also timing every plant and controller step into `costs`.
pub fn run_measured(
    plan: &Plan,
    mut costs: Option<&mut StepCosts>,
    mut on_step: impl FnMut(&StepRecord<'_>) -> std::io::Result<()>,
) -> Result<(), LoopError> {
    let plant_err = |cause| LoopError::Plant {
        robot: plan.robot.label(),
        cause,
    };
    let mut plant = crate::node::configs::plant(plan)
        .machine()
        .map_err(plant_err)?;
    let n = plant.dof();
    let mut controller = crate::node::configs::controller(plan).machine()?;
    let mut reference = TrajectoryMachine::new(plan.reference.clone(), plan.reference_period_ns);
    let mut records = RecordAssembler::new(n, plan.dt(), plan.steps);
    let mut state = plant.state(0, 0);
    for k in 0..plan.steps {
        let r = reference.sample(reference.index_at(state.header.t_ns), 0);
        let t0 = std::time::Instant::now();
        let (command, diagnostics) = controller.step(&state, Some(&r));
        let t1 = std::time::Instant::now();
        plant.step(Some(&command)).map_err(plant_err)?;
        if let Some(c) = costs.as_mut() {
            c.controller_us.add((t1 - t0).as_nanos() as f64 / 1e3);
            c.plant_us.add(t1.elapsed().as_nanos() as f64 / 1e3);
        }
        records.push_state(state);
        records.push_diag(diagnostics);
        state = plant.state(k + 1, 0);
        records.push_state(state);
        records
            .emit(&mut on_step)
            .map_err(|cause| LoopError::Sink { step: k, cause })?;
    }
    Ok(())
}
