//! `testbed sim`: the run in one process. The plant, trajectory and
//! controller step machines are called in order ([`Stepper`]) with the same
//! messages the nodes exchange, and the step records come from the same assembler that
//! reads a multi-process run's log: so lockstep reproduces this bit for bit.

use controller::ControllerError;
use plant_rapier::PlantError;
use scenario::Plan;

use scenario::stepper::Stepper;

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
    let mut stepper = Stepper::new(plan).map_err(plant_err)?;
    let mut controller = plan.controller_config().machine()?;
    let mut records = RecordAssembler::new(stepper.dof(), plan.dt(), plan.steps);
    for k in 0..plan.steps {
        // State k goes in first: the rows come out as before, with no copy
        // of it kept for later.
        records.push_state(*stepper.state());
        let t0 = std::time::Instant::now();
        let (command, diagnostics) = stepper.command(&mut controller);
        let t1 = std::time::Instant::now();
        let stepped = stepper.advance(&command);
        // The plant's time includes reading state k+1 and its reference
        // sample, which the loop did outside the clock before the stepper.
        if let Some(c) = costs.as_mut() {
            c.controller_us.add((t1 - t0).as_nanos() as f64 / 1e3);
            c.plant_us.add(t1.elapsed().as_nanos() as f64 / 1e3);
        }
        stepped.map_err(plant_err)?;
        records.push_diag(diagnostics);
        records.push_state(*stepper.state());
        records
            .emit(&mut on_step)
            .map_err(|cause| LoopError::Sink { step: k, cause })?;
    }
    Ok(())
}
