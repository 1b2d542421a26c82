//! Message types. Every one is `Copy`, `#[repr(C)]` and has a versioned type name.

use iceoryx2::prelude::ZeroCopySend;

/// The largest arm the wire carries: dual arms and humanoid upper bodies.
/// An arm with more controlled joints is refused before anything starts
/// (`scenario::plan`, and each step machine's constructor).
pub const MAX_DOF: usize = 32;

/// Per-joint values; entries past `dof` are zero.
pub type Joints = [f64; MAX_DOF];

/// Copies `values` (at most [`MAX_DOF`]) into a zero-padded array.
pub fn joints(values: &[f64]) -> Joints {
    let mut out = [0.0; MAX_DOF];
    let n = values.len().min(MAX_DOF);
    out[..n].copy_from_slice(&values[..n]);
    out
}

/// The first part of every sample.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
pub struct Header {
    /// Sequence number: the control step for step-aligned topics, else a
    /// per-publisher counter from 0.
    pub seq: u64,
    /// Sim time the sample refers to, ns.
    pub t_ns: u64,
    /// CLOCK_MONOTONIC when the sample was published, ns (comparable across
    /// processes on one machine).
    pub wall_ns: u64,
}

/// `JointState::flags`: the last state of the run; no command is expected for it.
pub const STATE_FINAL: u32 = 1;

/// A sequence number or sim time that does not exist: no command applied
/// yet ([`JointState::command_seq`]), no reference sample
/// ([`Command::reference_t_ns`]).
pub const NONE_U64: u64 = u64::MAX;

crate::data_message! {
    /// The plant's state at step `header.seq` (t_k = k Δt).
    #[type_name("testbed.JointState.v4")]
    pub struct JointState {
        /// seq = k, t_ns = t_k.
        header: Header,
        /// Joints in use.
        dof: u32 => U32,
        /// [`STATE_FINAL`].
        flags: u32 => U32,
        /// The true joint positions q(t_k) (for analysis; the controller gets
        /// `q_measured`).
        q: Joints => J,
        /// The true joint velocities q̇(t_k).
        qd: Joints => J,
        /// What the position sensors report (noise, quantisation).
        q_measured: Joints => J,
        /// What the velocity sensors report.
        qd_measured: Joints => J,
        /// The motor torque the plant applied over [t_{k−1}, t_k] (zero for k = 0).
        tau_applied: Joints => J,
        /// The disturbance d applied over [t_{k−1}, t_k].
        disturbance: Joints => J,
        /// Which plant effects acted on this state: the bits of
        /// `plant_rapier::Effects` (friction, payload, saturated, …).
        effects: u32 => U32,
        /// Padding (keeps the layout explicit).
        reserved: u32 => Pad,
        /// Deadline misses so far (real-time mode).
        deadline_misses: u64 => U64,
        /// Seq of the command the plant applied over [t_{k−1}, t_k]
        /// ([`NONE_U64`] at k = 0 or before any came). Anything but k − 1
        /// is a deadline miss: the log recounts them from this.
        command_seq: u64 => U64 | NONE_U64,
        /// CLOCK_MONOTONIC when the plant took that command (its wake-up
        /// for t_k in real time; its arrival in lockstep), ns; 0 if none.
        applied_wall_ns: u64 => U64 | 0,
    }
}

crate::data_message! {
    /// The reference and envelope at `header.t_ns`.
    #[type_name("testbed.Reference.v2")]
    pub struct ReferenceSample {
        /// seq counts samples, t_ns is the time they describe.
        header: Header,
        /// Joints in use.
        dof: u32 => U32,
        /// Padding (keeps the layout explicit).
        reserved: u32 => Pad,
        /// q_d.
        q_d: Joints => J,
        /// q̇_d.
        qd_d: Joints => J,
        /// q̈_d.
        qdd_d: Joints => J,
        /// k_c.
        kc: Joints => J,
        /// k̇_c.
        kc_dot: Joints => J,
    }
}

crate::data_message! {
    /// The controller's torque for the state with the same `header.seq`.
    #[type_name("testbed.Command.v3")]
    pub struct Command {
        /// seq and t_ns of the state this answers; wall_ns when it was sent.
        header: Header,
        /// Joints in use.
        dof: u32 => U32,
        /// Non-zero: the controller published zero torque because of a fault.
        fault: u32 => U32,
        /// Joint torques (forces for prismatic joints).
        tau: Joints => J,
        /// wall_ns of the state this answers (for the round trip).
        state_wall_ns: u64 => U64,
        /// Controller compute time for this step, ns.
        compute_ns: u64 => U64,
        /// CLOCK_MONOTONIC when the controller started on the state, ns:
        /// minus the state's `wall_ns`, the state's age.
        started_wall_ns: u64 => U64 | 0,
        /// Sim time of the reference sample used ([`NONE_U64`]: none had
        /// come). Older than the sample for the state's own time: a stale
        /// reference.
        reference_t_ns: u64 => U64 | NONE_U64,
        /// Stale references so far, this step included: the controller's
        /// own count, which the log's recount must equal.
        stale_references: u64 => U64 | 0,
    }
}

crate::data_message! {
    /// Everything the controller computed at one step (SPEC §12).
    #[type_name("testbed.ControllerDiagnostics.v3")]
    pub struct ControllerDiagnostics {
        /// seq and t_ns of the state acted on.
        header: Header,
        /// Joints in use.
        dof: u32 => U32,
        /// Fault code (0 = none).
        fault: u32 => U32,
        /// 1 if the guard clamped D this step.
        barrier_breached: u32 => U32,
        /// Padding.
        reserved: u32 => Pad,
        /// Controller compute time, ns.
        compute_ns: u64 => U64,
        /// γ(t).
        gamma: f64 => F64,
        /// γ̇(t).
        gamma_dot: f64 => F64,
        /// Ĵ.
        j_hat: f64 => F64,
        /// δ.
        delta: f64 => F64,
        /// r.
        r: f64 => F64,
        /// ‖Ŵ_c‖ before the update.
        wc_norm: f64 => F64,
        /// The reference used: q_d.
        q_d: Joints => J,
        /// The reference used: q̇_d.
        qd_d: Joints => J,
        /// The reference used: q̈_d.
        qdd_d: Joints => J,
        /// The envelope used, per joint as given: k_c,i.
        kc_in: Joints => J,
        /// The envelope rate used: k̇_c,i.
        kc_dot: Joints => J,
        /// Z1.
        z1: Joints => J,
        /// Z1γ.
        z1g: Joints => J,
        /// Z2.
        z2: Joints => J,
        /// α.
        alpha: Joints => J,
        /// The bound each barrier used (min k_c in norm mode).
        kc: Joints => J,
        /// D before the guard.
        d: Joints => J,
        /// τ.
        tau: Joints => J,
        /// Actor term of τ.
        tau_actor: Joints => J,
        /// Feedback term of τ (−K2 Z2 for the paper's law).
        tau_feedback: Joints => J,
        /// Barrier term of τ.
        tau_barrier: Joints => J,
        /// Model term of a model-based law (G for `pd-gravity`, the whole
        /// computed torque for `ctc`, whose feedback acts through M; zero
        /// for the model-free laws).
        tau_model: Joints => J,
        /// ‖Ŵ_a‖ per joint before the update.
        wa_norm: Joints => J,
    }
}

/// Most values an external controller's own diagnostics carry a step
/// (one [`Joints`] array: every joint of the largest arm, or a few vectors
/// of a smaller one).
pub const MAX_OWN_DIAGNOSTICS: usize = MAX_DOF;

crate::data_message! {
    /// An external controller's own diagnostics of one step: the values of
    /// what it declared (`CMD --describe`), in the order the run's metadata
    /// (`controller_diagnostics`) lists them.
    #[type_name("testbed.OwnDiagnostics.v1")]
    pub struct OwnDiagnostics {
        /// seq and t_ns of the state acted on.
        header: Header,
        /// Values in use.
        count: u32 => U32,
        /// Padding.
        reserved: u32 => Pad,
        /// The values, the declared diagnostics one after another.
        values: Joints => V,
    }
}

crate::data_message! {
    /// What contact did over the period that led to the state with the same
    /// `header.seq` (published only by a plant with `[plant.contact]`).
    #[type_name("testbed.ContactState.v2")]
    pub struct ContactState {
        /// seq = k, t_ns = t_k.
        header: Header,
        /// Contact points at the period's last substep.
        points: u32 => U32,
        /// Values in `objects`: 7 per free object (0 in logs before objects
        /// were logged).
        count: u32 => U32 | 0,
        /// Mean contact force on the arm over the period: the contact
        /// solver's normal impulses summed over contacts and substeps, over
        /// the period, N.
        force: f64 => F64,
        /// The deepest contact point at the period's last substep, world
        /// frame, m (0 with no contact).
        point_x: f64 => F64,
        /// Its y, m.
        point_y: f64 => F64,
        /// Its z, m.
        point_z: f64 => F64,
        /// Each `[[plant.contact.object]]`'s pose at the period's end, world
        /// frame: x, y, z (m), then the quaternion x, y, z, w, one object
        /// after another ([`MAX_OBJECTS`] at most).
        objects: Joints => V | [0.0; MAX_DOF],
    }
}

/// The most free objects a contact scenario may have: [`ContactState`]
/// carries 7 numbers of pose for each in its [`MAX_DOF`] values.
pub const MAX_OBJECTS: usize = MAX_DOF / 7;

crate::data_message! {
    /// Timing of one plant cycle (published by the plant, which is the clock).
    #[type_name("testbed.Timing.v2")]
    pub struct Timing {
        /// seq = cycle k, t_ns = t_k.
        header: Header,
        /// How late the plant woke after its deadline, ns (real time; 0 in lockstep).
        wake_late_ns: i64 => I64,
        /// Wall time since the previous cycle's wake-up, ns (0 at k = 0).
        period_ns: i64 => I64,
        /// State k−1 published → its command sent, ns; −1 if it never came.
        round_trip_ns: i64 => I64,
        /// Controller compute time for step k−1, ns; −1 if unknown.
        controller_compute_ns: i64 => I64,
        /// 1 if the command for step k−1 had not arrived at this cycle's deadline.
        deadline_missed: u32 => U32,
        /// Padding.
        reserved: u32 => Pad,
        /// Deadline misses so far.
        deadline_misses: u64 => U64,
        /// Wake-ups late by a whole period so far of the timer floor, a
        /// bare sleep loop beside the plant on its CPU and grid
        /// (the timer floor); [`NONE_U64`]: none ran.
        floor_late_wakeups: u64 => U64 | NONE_U64,
    }
}

/// [`Control::command`]: start the run at `epoch_wall_ns`.
pub const CONTROL_START: u32 = 1;
/// [`Control::command`]: stop and exit.
pub const CONTROL_STOP: u32 = 2;

/// How a run ended, as the launcher tells the nodes with STOP and the log
/// records it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunEnd {
    /// Every step was made.
    Finished,
    /// Ctrl-C or SIGTERM of the launcher.
    Interrupted,
    /// The run failed otherwise (a stall, a start-up timeout, the bus).
    Failed,
    /// A node died or failed.
    LostNode(NodeKind),
}

impl RunEnd {
    /// The code carried in [`Control::code`] with STOP.
    pub fn code(self) -> u32 {
        match self {
            RunEnd::Finished => 0,
            RunEnd::Interrupted => 1,
            RunEnd::Failed => 2,
            RunEnd::LostNode(k) => 10 + k as u32,
        }
    }

    /// The outcome of a code (unknown codes read as a failure).
    pub fn from_code(code: u32) -> Self {
        match code {
            0 => RunEnd::Finished,
            1 => RunEnd::Interrupted,
            c => NodeKind::ALL
                .into_iter()
                .find(|k| 10 + *k as u32 == c)
                .map_or(RunEnd::Failed, RunEnd::LostNode),
        }
    }

    /// What the log says: "finished", "interrupted", "failed", "lost the plant".
    pub fn describe(self) -> String {
        match self {
            RunEnd::Finished => "finished".into(),
            RunEnd::Interrupted => "interrupted".into(),
            RunEnd::Failed => "failed".into(),
            RunEnd::LostNode(k) => format!("lost the {}", k.name()),
        }
    }
}

crate::data_message! {
    /// From the launcher to every node.
    #[type_name("testbed.Control.v2")]
    pub struct Control {
        /// seq counts control messages.
        header: Header,
        /// [`CONTROL_START`] or [`CONTROL_STOP`].
        command: u32 => U32,
        /// With START: the run's mode ([`crate::Mode::code`]), which every node
        /// checks against its own; with STOP: how the run ended ([`RunEnd::code`]).
        code: u32 => U32,
        /// CLOCK_MONOTONIC time of step 0, ns (with START).
        epoch_wall_ns: u64 => U64,
    }
}

/// Which process a [`NodeStatus`] is from.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeKind {
    /// The plant.
    Plant = 1,
    /// The trajectory generator.
    Trajectory = 2,
    /// The controller.
    Controller = 3,
    /// The logger.
    Logger = 4,
}

impl NodeKind {
    /// Every kind, in start order.
    pub const ALL: [NodeKind; 4] = [
        NodeKind::Plant,
        NodeKind::Trajectory,
        NodeKind::Controller,
        NodeKind::Logger,
    ];

    /// The name used on the command line (`testbed node <name>`).
    pub fn name(self) -> &'static str {
        match self {
            NodeKind::Plant => "plant",
            NodeKind::Trajectory => "trajectory",
            NodeKind::Controller => "controller",
            NodeKind::Logger => "logger",
        }
    }

    /// From the wire value.
    pub fn from_u32(v: u32) -> Option<Self> {
        Self::ALL.into_iter().find(|k| *k as u32 == v)
    }
}

/// [`NodeStatus::state`]: connected and waiting for START.
pub const NODE_READY: u32 = 1;
/// [`NodeStatus::state`]: running.
pub const NODE_RUNNING: u32 = 2;
/// [`NodeStatus::state`]: finished its part of the run.
pub const NODE_DONE: u32 = 3;
/// [`NodeStatus::state`]: failed; `code` says why.
pub const NODE_FAILED: u32 = 4;

crate::data_message! {
    /// From every node to the launcher.
    #[type_name("testbed.NodeStatus.v1")]
    pub struct NodeStatus {
        /// seq counts this node's status messages.
        header: Header,
        /// [`NodeKind`] as u32.
        node: u32 => U32,
        /// NODE_READY, NODE_RUNNING, NODE_DONE or NODE_FAILED.
        state: u32 => U32,
        /// The node's process id.
        pid: u32 => U32,
        /// Padding.
        reserved: u32 => Pad,
        /// Steps the node has handled.
        step: u64 => U64,
    }
}
