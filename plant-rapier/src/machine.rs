//! The plant's step machine: command → state, in wire messages. The plant
//! node, `testbed sim` and the benchmarks all drive this one machine, so a
//! lockstep run and an in-process one compute the same bits.

use wire::{Command, ContactState, Header, JointState, MAX_DOF, NONE_U64, STATE_FINAL, joints};

use crate::{ArmModel, PlantConfig, PlantError, Rig};

/// Everything a [`PlantMachine`] is built from, and the one way to build
/// one ([`PlantMachineConfig::machine`]): the plant node, `testbed sim` and
/// the Gym environment all go through it, so they cannot drift apart.
#[derive(Debug, Clone)]
pub struct PlantMachineConfig {
    /// The arm (its locked joints already held).
    pub model: ArmModel,
    /// Plant settings.
    pub plant: PlantConfig,
    /// Seed of every random effect.
    pub seed: u64,
    /// Control period, ns.
    pub period_ns: u64,
    /// Steps in the run (state `steps` is flagged final).
    pub steps: u64,
    /// q(0), one per controlled joint.
    pub initial_q: Vec<f64>,
    /// q̇(0), one per controlled joint.
    pub initial_qd: Vec<f64>,
}

impl PlantMachineConfig {
    /// The machine this config describes, at its initial state.
    pub fn machine(&self) -> Result<PlantMachine, PlantError> {
        PlantMachine::new(
            &self.model,
            &self.plant,
            self.seed,
            self.period_ns,
            self.steps,
            (&self.initial_q, &self.initial_qd),
        )
    }
}

/// The rig stepped a period at a time, its states as [`JointState`]s.
#[derive(Debug)]
pub struct PlantMachine {
    rig: Rig,
    n: usize,
    period_ns: u64,
    steps: u64,
    q: Vec<f64>,
    qd: Vec<f64>,
    q_meas: Vec<f64>,
    qd_meas: Vec<f64>,
    /// Deadline misses so far (the real-time node counts them).
    pub misses: u64,
    /// Seq of the newest command taken ([`NONE_U64`] before the first).
    taken_seq: u64,
}

impl PlantMachine {
    /// The rig for `model` at `q0`, `qd0`, stepping periods of `period_ns`
    /// for `steps` steps (built through [`PlantMachineConfig::machine`]).
    fn new(
        model: &ArmModel,
        config: &PlantConfig,
        seed: u64,
        period_ns: u64,
        steps: u64,
        (q0, qd0): (&[f64], &[f64]),
    ) -> Result<Self, PlantError> {
        // A state carries at most MAX_DOF joints; more would be cut off.
        if model.dof() > MAX_DOF {
            return Err(PlantError::TooManyJoints(model.dof()));
        }
        let scaled;
        let model = if config.mass_scale == 1.0 {
            model
        } else {
            scaled = scale_masses(model, config.mass_scale);
            &scaled
        };
        let mut rig = Rig::new(model, config, seed, period_ns)?;
        // Refused before the first step, not hours into it.
        rig.plant().period_cost(period_ns as f64 / 1e9)?;
        rig.set_state(q0, qd0)?;
        let n = rig.dof();
        Ok(Self {
            rig,
            n,
            period_ns,
            steps,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            q_meas: vec![0.0; n],
            qd_meas: vec![0.0; n],
            misses: 0,
            taken_seq: NONE_U64,
        })
    }

    /// Number of controlled joints.
    pub fn dof(&self) -> usize {
        self.n
    }

    /// What a period costs the engine ([`crate::Plant::period_cost`]).
    pub fn period_cost(&self) -> Result<crate::PeriodCost, PlantError> {
        self.rig.plant().period_cost(self.period_ns as f64 / 1e9)
    }

    /// A warning, to say before the run, when the substeps the engine adds
    /// for stiff springs or damping make the plant alone slower than real
    /// time: the estimated factor, from substeps timed on a copy of the
    /// arm (the fastest of five looks at 128, well under a millisecond's
    /// worth).
    pub fn speed_warning(&self) -> Result<Option<String>, PlantError> {
        let cost = self.period_cost()?;
        if cost.cause.is_none() {
            return Ok(None);
        }
        let dt = self.period_ns as f64 / 1e9;
        // The fastest of a few looks: another process's time slice is the
        // machine's load, not the plant's cost (one look on a loaded
        // machine once warned of a scenario that keeps up 14 times over).
        let fastest = (0..5)
            .filter_map(|_| self.rig.plant().time_substeps(dt, 128))
            .reduce(f64::min);
        Ok(fastest.and_then(|s| cost.warning(s)))
    }

    /// Control period, ns.
    pub fn period_ns(&self) -> u64 {
        self.period_ns
    }

    /// Steps in the run.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// State k as published, stamped `wall_ns`: the true state, the sensors'
    /// reading (drawn here, once per state) and the effects of the period
    /// that led to it. State `steps` is flagged final.
    pub fn state(&mut self, k: u64, wall_ns: u64) -> JointState {
        self.rig.true_state_into(&mut self.q, &mut self.qd);
        self.rig.measure_into(&mut self.q_meas, &mut self.qd_meas);
        let first = k == 0;
        JointState {
            header: Header {
                seq: k,
                t_ns: k * self.period_ns,
                wall_ns,
            },
            dof: self.n as u32,
            flags: if k == self.steps { STATE_FINAL } else { 0 },
            q: joints(&self.q),
            qd: joints(&self.qd),
            q_measured: joints(&self.q_meas),
            qd_measured: joints(&self.qd_meas),
            // What the plant really applied: the command after delay, loss
            // and saturation.
            tau_applied: if first {
                [0.0; MAX_DOF]
            } else {
                joints(self.rig.applied_torque())
            },
            disturbance: if first {
                [0.0; MAX_DOF]
            } else {
                joints(self.rig.disturbance())
            },
            effects: self.rig.effects().0,
            reserved: 0,
            deadline_misses: self.misses,
            command_seq: self.taken_seq,
            // Clock data: the node stamps it.
            applied_wall_ns: 0,
        }
    }

    /// Whether the plant simulates contact (and so publishes
    /// [`PlantMachine::contact`] beside each state).
    pub fn has_contact(&self) -> bool {
        self.rig.plant().contact().is_some()
    }

    /// What contact did over the period that led to state k, stamped as
    /// that state; `None` without `[plant.contact]`.
    pub fn contact(&self, k: u64, wall_ns: u64) -> Option<ContactState> {
        let c = self.rig.plant().contact()?;
        Some(ContactState {
            header: Header {
                seq: k,
                t_ns: k * self.period_ns,
                wall_ns,
            },
            points: c.points,
            count: (7 * c.n_objects) as u32,
            force: c.force,
            point_x: c.point[0],
            point_y: c.point[1],
            point_z: c.point[2],
            objects: {
                let mut v = [0.0; wire::MAX_DOF];
                for (out, pose) in v.chunks_exact_mut(7).zip(&c.objects[..c.n_objects]) {
                    out.copy_from_slice(pose);
                }
                v
            },
        })
    }

    /// Steps one period with `cmd` (None: no new command, the last is held).
    pub fn step(&mut self, cmd: Option<&Command>) -> Result<(), PlantError> {
        if let Some(c) = cmd
            && c.dof as usize != self.n
        {
            return Err(PlantError::WrongLength {
                field: "command tau",
                expected: self.n,
                got: c.dof as usize,
            });
        }
        if let Some(c) = cmd {
            self.taken_seq = c.header.seq;
        }
        self.rig.step(cmd.map(|c| &c.tau[..self.n]))
    }
}

/// `model` with every link's mass and inertia times `s` (the plant's
/// `mass_scale`; the centres of mass stay).
fn scale_masses(model: &ArmModel, s: f64) -> ArmModel {
    let mut m = model.clone();
    for link in &mut m.links {
        link.mass *= s;
        link.inertia = link.inertia.map(|x| x * s);
    }
    m
}
