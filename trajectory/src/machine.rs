//! The trajectory's step machine: sample index → reference sample, in wire
//! messages. The trajectory node and `testbed sim` both drive it.

use wire::{Header, joints};

use crate::{Reference, ReferenceSample};

/// Everything a [`TrajectoryMachine`] is built from, and the one way to
/// build one ([`TrajectoryMachineConfig::machine`]): the trajectory node,
/// `testbed sim` and the Gym environment all go through it.
#[derive(Debug, Clone)]
pub struct TrajectoryMachineConfig {
    /// The checked reference and envelope.
    pub reference: Reference,
    /// Period of the samples, ns (0 is taken as 1).
    pub reference_period_ns: u64,
}

impl TrajectoryMachineConfig {
    /// The machine this config describes.
    pub fn machine(&self) -> TrajectoryMachine {
        TrajectoryMachine::new(self.reference.clone(), self.reference_period_ns)
    }
}

/// Sample j describes t_j = j × the reference period.
#[derive(Debug, Clone)]
pub struct TrajectoryMachine {
    reference: Reference,
    period_ns: u64,
    buf: ReferenceSample,
}

impl TrajectoryMachine {
    /// Samples of `reference` every `period_ns` (> 0; built through
    /// [`TrajectoryMachineConfig::machine`]).
    fn new(reference: Reference, period_ns: u64) -> Self {
        Self {
            buf: ReferenceSample::new(reference.dof()),
            reference,
            period_ns: period_ns.max(1),
        }
    }

    /// The reference period, ns.
    pub fn period_ns(&self) -> u64 {
        self.period_ns
    }

    /// The index of the newest sample at or before `t_ns`: the one a
    /// controller at `t_ns` uses.
    pub fn index_at(&self, t_ns: u64) -> u64 {
        t_ns / self.period_ns
    }

    /// Sample `j`, stamped `wall_ns`.
    pub fn sample(&mut self, j: u64, wall_ns: u64) -> wire::ReferenceSample {
        let t_ns = j * self.period_ns;
        self.reference
            .sample_into(wire::ns_to_s(t_ns), &mut self.buf);
        let r = &self.buf;
        wire::ReferenceSample {
            header: Header {
                seq: j,
                t_ns,
                wall_ns,
            },
            dof: r.q_d.len() as u32,
            reserved: 0,
            q_d: joints(&r.q_d),
            qd_d: joints(&r.qd_d),
            qdd_d: joints(&r.qdd_d),
            kc: joints(&r.kc),
            kc_dot: joints(&r.kc_dot),
        }
    }
}
