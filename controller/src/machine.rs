//! The controller's step machine: joint state + reference → command +
//! diagnostics, in wire messages. The controller node, `testbed sim` and
//! `replay --verify` all drive this one machine.

use wire::{Command, ControllerDiagnostics, Header, JointState, ReferenceSample, joints};

use arm_model::ArmModel;

use crate::{ControllerError, ControllerInput, ControllerParams, Diagnostics, Fault, Law};

/// Everything a [`ControllerMachine`] is built from, and the one way to
/// build one ([`ControllerMachineConfig::machine`]): the controller node,
/// `testbed sim`, `replay --verify` and the Gym environment's base law all
/// go through it.
#[derive(Debug, Clone)]
pub struct ControllerMachineConfig {
    /// The law's parameters.
    pub params: ControllerParams,
    /// Controlled joints.
    pub dof: usize,
    /// Control period, ns.
    pub period_ns: u64,
    /// The arm's model, which only the model-based laws read (None for the
    /// others).
    pub model: Option<ArmModel>,
}

impl ControllerMachineConfig {
    /// The machine this config describes (sizes checked first, as a config
    /// written by hand may be wrong).
    pub fn machine(&self) -> Result<ControllerMachine, ControllerError> {
        if self.dof == 0 || self.dof > wire::MAX_DOF || self.period_ns == 0 {
            return Err(ControllerError::InvalidParameter {
                key: "dof".into(),
                value: format!("{} joints, period {} ns", self.dof, self.period_ns),
                need: format!("1 to {} joints and a period above 0", wire::MAX_DOF),
            });
        }
        ControllerMachine::new(&self.params, self.dof, self.period_ns, self.model.as_ref())
    }
}

/// The law behind wire messages.
#[derive(Debug)]
pub struct ControllerMachine {
    law: Law,
    diag: Diagnostics,
    n: usize,
    dt: f64,
}

impl ControllerMachine {
    /// The law with `params` for `dof` joints at a period of `period_ns`;
    /// `model` is the arm's, which only the model-based laws read (built
    /// through [`ControllerMachineConfig::machine`]).
    fn new(
        params: &ControllerParams,
        dof: usize,
        period_ns: u64,
        model: Option<&ArmModel>,
    ) -> Result<Self, ControllerError> {
        // `step` slices the wire's fixed arrays to `dof`.
        if dof > wire::MAX_DOF {
            return Err(ControllerError::TooManyJoints(dof));
        }
        let law = Law::new(params, dof, model)?;
        Ok(Self {
            diag: Diagnostics::new(dof),
            law,
            n: dof,
            dt: wire::ns_to_s(period_ns),
        })
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.n
    }

    /// The diagnostics of the last step.
    pub fn diagnostics(&self) -> &Diagnostics {
        &self.diag
    }

    /// One step on the measured `state` with `reference` (None: no sample
    /// is available, which publishes zero torque with a fault). The
    /// messages carry the state's seq and sim time; their wall stamps and
    /// compute time are the caller's to set.
    pub fn step(
        &mut self,
        state: &JointState,
        reference: Option<&ReferenceSample>,
    ) -> (Command, ControllerDiagnostics) {
        let n = self.n;
        let zero = ReferenceSample::default();
        match reference {
            Some(r) => {
                let input = ControllerInput {
                    t: wire::ns_to_s(state.header.t_ns),
                    q: &state.q_measured[..n],
                    qd: &state.qd_measured[..n],
                    q_d: &r.q_d[..n],
                    qd_d: &r.qd_d[..n],
                    qdd_d: &r.qdd_d[..n],
                    kc: &r.kc[..n],
                    kc_dot: &r.kc_dot[..n],
                };
                self.law.step(self.dt, &input, &mut self.diag);
            }
            None => {
                self.diag.fault = Some(Fault::NoReference);
                self.diag.tau.iter_mut().for_each(|x| *x = 0.0);
            }
        }
        let header = Header {
            seq: state.header.seq,
            t_ns: state.header.t_ns,
            wall_ns: 0,
        };
        let d = &self.diag;
        let command = Command {
            header,
            dof: n as u32,
            fault: d.fault.map_or(0, |f| f.code()),
            tau: joints(&d.tau),
            state_wall_ns: state.header.wall_ns,
            compute_ns: 0,
            started_wall_ns: 0,
            reference_t_ns: reference.map_or(wire::NONE_U64, |r| r.header.t_ns),
            // The node's count (it knows which sample was due).
            stale_references: 0,
        };
        (command, diag_msg(header, d, reference.unwrap_or(&zero)))
    }
}

fn diag_msg(header: Header, d: &Diagnostics, r: &ReferenceSample) -> ControllerDiagnostics {
    ControllerDiagnostics {
        header,
        dof: d.tau.len() as u32,
        fault: d.fault.map_or(0, |f| f.code()),
        barrier_breached: u32::from(d.barrier_breached),
        reserved: 0,
        compute_ns: 0,
        gamma: d.gamma,
        gamma_dot: d.gamma_dot,
        j_hat: d.j_hat,
        delta: d.delta,
        r: d.r,
        wc_norm: d.wc_norm,
        q_d: r.q_d,
        qd_d: r.qd_d,
        qdd_d: r.qdd_d,
        kc_in: r.kc,
        kc_dot: r.kc_dot,
        z1: joints(&d.z1),
        z1g: joints(&d.z1g),
        z2: joints(&d.z2),
        alpha: joints(&d.alpha),
        kc: joints(&d.kc),
        d: joints(&d.d),
        tau: joints(&d.tau),
        tau_actor: joints(&d.tau_actor),
        tau_feedback: joints(&d.tau_feedback),
        tau_barrier: joints(&d.tau_barrier),
        tau_model: joints(&d.tau_model),
        wa_norm: joints(&d.wa_norm),
    }
}
