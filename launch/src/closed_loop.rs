//! The closed loop in one process: plant, reference and controller stepped
//! in turn, as fast as the machine allows. `testbed sim` is this loop; the
//! multi-process lockstep mode must reproduce it bit for bit.

use controller::{Controller, ControllerError, ControllerInput};
use plant_rapier::{PlantError, Rig};
use scenario::{Plan, ns_to_s};
use trajectory::ReferenceSample;

use crate::record::StepRecord;

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

/// Wall time of each plant and controller step, ns (for benchmarks).
#[derive(Debug, Default, Clone)]
pub struct StepCosts {
    /// One entry per plant step.
    pub plant_ns: Vec<u64>,
    /// One entry per controller step.
    pub controller_ns: Vec<u64>,
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
    let robot = plan.robot.label();
    let plant_err = |cause| LoopError::Plant {
        robot: robot.clone(),
        cause,
    };
    let s = &plan.scenario;
    let mut rig =
        Rig::new(&plan.robot.model, &s.plant, s.seed, plan.period_ns).map_err(plant_err)?;
    rig.set_state(&s.initial.q, &s.initial.qd)
        .map_err(plant_err)?;
    let n = rig.dof();
    let mut controller = Controller::new(s.controller.clone(), n)?;
    let mut diag = controller.diagnostics();
    let mut reference = ReferenceSample::new(n);
    let dt = plan.dt();

    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    let (mut qm, mut qdm) = (vec![0.0; n], vec![0.0; n]);
    rig.true_state_into(&mut q, &mut qd);
    let (mut q_next, mut qd_next) = (vec![0.0; n], vec![0.0; n]);
    let mut qdd = vec![0.0; n];
    for k in 0..plan.steps {
        let t_ns = plan.t_ns(k);
        let t = ns_to_s(t_ns);
        // The sensors are read once per state, as the plant process does.
        rig.measure_into(&mut qm, &mut qdm);
        plan.reference
            .sample_into(ns_to_s(plan.reference_t_ns(t_ns)), &mut reference);
        let input = ControllerInput {
            t,
            q: &qm,
            qd: &qdm,
            q_d: &reference.q_d,
            qd_d: &reference.qd_d,
            kc: &reference.kc,
            kc_dot: &reference.kc_dot,
        };
        let t0 = std::time::Instant::now();
        controller.step(dt, &input, &mut diag);
        let t1 = std::time::Instant::now();
        rig.step(Some(&diag.tau)).map_err(plant_err)?;
        if let Some(c) = costs.as_mut() {
            c.controller_ns.push((t1 - t0).as_nanos() as u64);
            c.plant_ns.push(t1.elapsed().as_nanos() as u64);
        }
        rig.true_state_into(&mut q_next, &mut qd_next);
        for i in 0..n {
            qdd[i] = (qd_next[i] - qd[i]) / dt;
        }
        let record = StepRecord {
            t,
            q: &q,
            qd: &qd,
            q_measured: &qm,
            qd_measured: &qdm,
            qdd: &qdd,
            tau: rig.applied_torque(),
            disturbance: rig.disturbance(),
            effects: rig.effects().0,
            q_d: &reference.q_d,
            qd_d: &reference.qd_d,
            kc: &reference.kc,
            z1: &diag.z1,
            z1g: &diag.z1g,
            z2: &diag.z2,
            wa_norm: &diag.wa_norm,
            barrier_breached: diag.barrier_breached,
            fault: diag.fault.is_some(),
        };
        on_step(&record).map_err(|cause| LoopError::Sink { step: k, cause })?;
        std::mem::swap(&mut q, &mut q_next);
        std::mem::swap(&mut qd, &mut qd_next);
    }
    Ok(())
}
