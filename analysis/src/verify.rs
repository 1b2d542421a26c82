//! Replay as verification: re-drive the controller from a log's states and
//! the references it used, and compare its torques with the logged ones.

use std::collections::BTreeMap;

use controller::ControllerMachine;
use wire::{Command, ControllerDiagnostics, JointState, ReferenceSample};

/// Re-drives a fresh controller machine step by step.
pub struct Verifier {
    machine: ControllerMachine,
    n: usize,
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
    /// The run's controller machine, fresh.
    pub fn new(machine: ControllerMachine) -> Self {
        Self {
            n: machine.dof(),
            machine,
            next: 0,
            states: BTreeMap::new(),
            diags: BTreeMap::new(),
            commands: BTreeMap::new(),
            max_abs_torque_diff: 0.0,
            steps: 0,
        }
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
            // The reference the controller used, as its diagnostics record it.
            let reference = ReferenceSample {
                header: d.header,
                dof: d.dof,
                reserved: 0,
                q_d: d.q_d,
                qd_d: d.qd_d,
                qdd_d: d.qdd_d,
                kc: d.kc_in,
                kc_dot: d.kc_dot,
            };
            let used = (d.fault != controller::Fault::NoReference.code()).then_some(&reference);
            let (replayed, _) = self.machine.step(s, used);
            for (a, b) in replayed.tau[..n].iter().zip(&c.tau[..n]) {
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
