//! The policy as a controller law: joint state and reference sample in,
//! command and diagnostics out, acting as the Gymnasium environment does
//! (a new action every `decimation` plant periods on the environment's
//! observation, held, ramped or low-pass filtered in between as the
//! record says, added to the base law's torque every period). No clock, no I/O: the node binary is the shell around it.

use controller::node::ControllerNodeConfig;
use controller::{ControllerError, ControllerMachine};
use wire::{Command, ControllerDiagnostics, Header, JointState, ReferenceSample, joints};

use crate::{Policy, PolicyError};

/// A policy stepping as a law.
#[derive(Debug)]
pub struct PolicyLaw {
    policy: Policy,
    base: Option<ControllerMachine>,
    obs: Vec<f64>,
    action: Vec<f64>,
    /// The decision's torque, before smoothing.
    target: Vec<f64>,
    /// The last decision's clipped action (zero before the first).
    last_action: Vec<f64>,
    /// Spreads `target` over the decision's periods, as the environment.
    shaper: gym_env::ActionShaper,
}

impl PolicyLaw {
    /// The policy with its base law (if it is a residual) built from the
    /// run's controller config: the run's parameters carried over to the
    /// base law as `compare` matches laws (`ControllerParams::for_law`).
    pub fn new(policy: Policy, config: &ControllerNodeConfig) -> Result<Self, ControllerError> {
        let r = policy.record();
        let base = match r.base_law {
            None => None,
            Some(law) => {
                let mut c = config.clone();
                if c.params.law != law {
                    c.params = c.params.for_law(law);
                }
                Some(c.machine()?)
            }
        };
        // Plan::dt's expression: the low-pass's factor to the bit.
        let dt = config.period_ns as f64 / 1e9;
        Ok(Self {
            obs: vec![0.0; r.obs_dim],
            action: vec![0.0; r.dof],
            target: vec![0.0; r.dof],
            last_action: vec![0.0; r.dof],
            shaper: gym_env::ActionShaper::new(r.smoothing, r.decimation, dt, r.dof),
            base,
            policy,
        })
    }

    /// The policy it plays.
    pub fn policy(&self) -> &Policy {
        &self.policy
    }

    /// One plant period: state k (its seq) with the reference sample due.
    /// A decision is taken when k is a multiple of the decimation, as the
    /// environment's (whose episode starts at k = 0). Without a reference
    /// sample, or with a network that fails, the torque is zero with a
    /// fault, as the testbed's laws answer a fault; the error is returned
    /// beside for the node to report.
    pub fn step(
        &mut self,
        state: &JointState,
        reference: Option<&ReferenceSample>,
    ) -> (Command, ControllerDiagnostics, Option<PolicyError>) {
        let r = self.policy.record();
        let n = r.dof;
        let mut err = None;
        let (mut cmd, mut diag) = match self.base.as_mut() {
            Some(base) => base.step(state, reference),
            None => zero(state, reference, n),
        };
        if let Some(reference) = reference {
            let k = state.header.seq;
            if k.is_multiple_of(u64::from(r.decimation)) {
                gym_env::observe(
                    state,
                    reference,
                    k,
                    r.steps,
                    r.scale_obs,
                    &r.velocity_scale,
                    &mut self.obs,
                );
                if r.observe_action {
                    gym_env::observe_action(&self.last_action, &mut self.obs);
                }
                match self.policy.act(&self.obs, &mut self.action) {
                    Ok(()) => {
                        gym_env::action_torque(
                            &self.action,
                            r.span(),
                            &r.torque_scale,
                            &mut self.target,
                        );
                        self.shaper.decide(&self.target);
                        for (last, a) in self.last_action.iter_mut().zip(&self.action) {
                            *last = a.clamp(-1.0, 1.0);
                        }
                    }
                    Err(e) => {
                        self.shaper.reset();
                        self.last_action.fill(0.0);
                        err = Some(e);
                    }
                }
            }
        }
        // Every plant period, with or without a reference sample: the
        // shaper counts periods as the environment's does.
        let add = self.shaper.period_torque();
        if reference.is_some() {
            if err.is_some() {
                cmd.tau = [0.0; wire::MAX_DOF];
                cmd.fault = wire::Fault::NonFiniteOutput.code();
            } else {
                // The environment's order: the law's torque, then += the
                // action's (x + 0.0 is x).
                for (t, a) in cmd.tau.iter_mut().zip(add) {
                    *t += a;
                }
            }
            diag.tau = cmd.tau;
            diag.fault = cmd.fault;
            diag.tau_feedback = joints(add);
        }
        (cmd, diag, err)
    }
}

/// Zero torque stamped for `state` (what a torque policy's action adds to).
fn zero(
    state: &JointState,
    reference: Option<&ReferenceSample>,
    n: usize,
) -> (Command, ControllerDiagnostics) {
    let header = Header {
        seq: state.header.seq,
        t_ns: state.header.t_ns,
        wall_ns: 0,
    };
    let r = reference.copied().unwrap_or_default();
    let mut d = ControllerDiagnostics {
        header,
        dof: n as u32,
        q_d: r.q_d,
        qd_d: r.qd_d,
        kc_in: r.kc,
        kc_dot: r.kc_dot,
        kc: r.kc,
        ..ControllerDiagnostics::default()
    };
    for i in 0..n {
        d.z1[i] = state.q_measured[i] - r.q_d[i];
        d.z1g[i] = d.z1[i];
        d.z2[i] = state.qd_measured[i] - r.qd_d[i];
    }
    let command = Command {
        header,
        dof: n as u32,
        fault: if reference.is_none() {
            wire::Fault::NoReference.code()
        } else {
            0
        },
        tau: [0.0; wire::MAX_DOF],
        state_wall_ns: state.header.wall_ns,
        compute_ns: 0,
        started_wall_ns: 0,
        reference_t_ns: reference.map_or(wire::NONE_U64, |r| r.header.t_ns),
        stale_references: 0,
    };
    (command, d)
}
