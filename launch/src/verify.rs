//! Replay as verification: re-drive the controller from a log's states and
//! the references it used, and compare its torques with the logged ones.

use std::collections::BTreeMap;

use controller::{Controller, ControllerError, ControllerInput, Diagnostics};
use scenario::ns_to_s;
use wire::{Command, ControllerDiagnostics, JointState};

/// Re-drives a fresh controller step by step.
pub struct Verifier {
    law: Controller,
    diag: Diagnostics,
    n: usize,
    dt: f64,
    next: u64,
    states: BTreeMap<u64, JointState>,
    diags: BTreeMap<u64, ControllerDiagnostics>,
    commands: BTreeMap<u64, Command>,
    /// Largest |τ_replayed − τ_logged| so far.
    pub max_abs_torque_diff: f64,
    /// Steps compared.
    pub steps: u64,
}

impl Verifier {
    /// A controller with `params` for `n` joints at period `dt`.
    pub fn new(
        params: controller::ControllerParams,
        n: usize,
        dt: f64,
    ) -> Result<Self, ControllerError> {
        let law = Controller::new(params, n)?;
        Ok(Self {
            diag: law.diagnostics(),
            law,
            n,
            dt,
            next: 0,
            states: BTreeMap::new(),
            diags: BTreeMap::new(),
            commands: BTreeMap::new(),
            max_abs_torque_diff: 0.0,
            steps: 0,
        })
    }

    /// Adds a logged state.
    pub fn push_state(&mut self, s: JointState) {
        self.states.insert(s.header.seq, s);
        self.advance();
    }

    /// Adds logged diagnostics (they carry the reference the controller used).
    pub fn push_diag(&mut self, d: ControllerDiagnostics) {
        self.diags.insert(d.header.seq, d);
        self.advance();
    }

    /// Adds a logged command.
    pub fn push_command(&mut self, c: Command) {
        self.commands.insert(c.header.seq, c);
        self.advance();
    }

    fn advance(&mut self) {
        loop {
            let k = self.next;
            let (Some(s), Some(d), Some(c)) = (
                self.states.get(&k),
                self.diags.get(&k),
                self.commands.get(&k),
            ) else {
                return;
            };
            let n = self.n;
            let input = ControllerInput {
                t: ns_to_s(s.header.t_ns),
                q: &s.q_measured[..n],
                qd: &s.qd_measured[..n],
                q_d: &d.q_d[..n],
                qd_d: &d.qd_d[..n],
                kc: &d.kc_in[..n],
                kc_dot: &d.kc_dot[..n],
            };
            self.law.step(self.dt, &input, &mut self.diag);
            for (a, b) in self.diag.tau.iter().zip(&c.tau[..n]) {
                let diff = if a.to_bits() == b.to_bits() {
                    0.0
                } else {
                    (a - b).abs()
                };
                // NaN on one side only is the largest possible difference.
                let diff = if diff.is_nan() { f64::INFINITY } else { diff };
                self.max_abs_torque_diff = self.max_abs_torque_diff.max(diff);
            }
            self.steps += 1;
            self.states.remove(&k);
            self.diags.remove(&k);
            self.commands.remove(&k);
            self.next += 1;
        }
    }
}
