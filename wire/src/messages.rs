//! Message types. Every one is `Copy`, `#[repr(C)]` and has a versioned type name.

use iceoryx2::prelude::ZeroCopySend;

/// The largest arm the wire carries. An arm with more actuated joints is
/// refused before anything starts.
pub const MAX_DOF: usize = 12;

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

/// The plant's state at step `header.seq` (t_k = k Δt).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("testbed.JointState.v2")]
pub struct JointState {
    /// seq = k, t_ns = t_k.
    pub header: Header,
    /// Joints in use.
    pub dof: u32,
    /// [`STATE_FINAL`].
    pub flags: u32,
    /// The true joint positions q(t_k) (for analysis; the controller gets
    /// `q_measured`).
    pub q: Joints,
    /// The true joint velocities q̇(t_k).
    pub qd: Joints,
    /// What the position sensors report (noise, quantisation).
    pub q_measured: Joints,
    /// What the velocity sensors report.
    pub qd_measured: Joints,
    /// The motor torque the plant applied over [t_{k−1}, t_k] (zero for k = 0).
    pub tau_applied: Joints,
    /// The disturbance d applied over [t_{k−1}, t_k].
    pub disturbance: Joints,
    /// Which plant effects acted on this state: the bits of
    /// `plant_rapier::Effects` (friction, payload, saturated, …).
    pub effects: u32,
    /// Padding (keeps the layout explicit).
    pub reserved: u32,
    /// Deadline misses so far (real-time mode).
    pub deadline_misses: u64,
}

/// The reference and envelope at `header.t_ns`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("testbed.Reference.v1")]
pub struct ReferenceSample {
    /// seq counts samples, t_ns is the time they describe.
    pub header: Header,
    /// Joints in use.
    pub dof: u32,
    /// Padding (keeps the layout explicit).
    pub reserved: u32,
    /// q_d.
    pub q_d: Joints,
    /// q̇_d.
    pub qd_d: Joints,
    /// q̈_d.
    pub qdd_d: Joints,
    /// k_c.
    pub kc: Joints,
    /// k̇_c.
    pub kc_dot: Joints,
}

/// The controller's torque for the state with the same `header.seq`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("testbed.Command.v1")]
pub struct Command {
    /// seq and t_ns of the state this answers; wall_ns when it was sent.
    pub header: Header,
    /// Joints in use.
    pub dof: u32,
    /// Non-zero: the controller published zero torque because of a fault.
    pub fault: u32,
    /// Joint torques (forces for prismatic joints).
    pub tau: Joints,
    /// wall_ns of the state this answers (for the round trip).
    pub state_wall_ns: u64,
    /// Controller compute time for this step, ns.
    pub compute_ns: u64,
}

/// Everything the controller computed at one step (SPEC §12).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("testbed.ControllerDiagnostics.v1")]
pub struct ControllerDiagnostics {
    /// seq and t_ns of the state acted on.
    pub header: Header,
    /// Joints in use.
    pub dof: u32,
    /// Fault code (0 = none).
    pub fault: u32,
    /// 1 if the guard clamped D this step.
    pub barrier_breached: u32,
    /// Padding.
    pub reserved: u32,
    /// Controller compute time, ns.
    pub compute_ns: u64,
    /// γ(t).
    pub gamma: f64,
    /// γ̇(t).
    pub gamma_dot: f64,
    /// Ĵ.
    pub j_hat: f64,
    /// δ.
    pub delta: f64,
    /// r.
    pub r: f64,
    /// ‖Ŵ_c‖ before the update.
    pub wc_norm: f64,
    /// The reference used: q_d.
    pub q_d: Joints,
    /// The reference used: q̇_d.
    pub qd_d: Joints,
    /// The envelope used, per joint as given: k_c,i.
    pub kc_in: Joints,
    /// The envelope rate used: k̇_c,i.
    pub kc_dot: Joints,
    /// Z1.
    pub z1: Joints,
    /// Z1γ.
    pub z1g: Joints,
    /// Z2.
    pub z2: Joints,
    /// α.
    pub alpha: Joints,
    /// The bound each barrier used (min k_c in norm mode).
    pub kc: Joints,
    /// D before the guard.
    pub d: Joints,
    /// τ.
    pub tau: Joints,
    /// Actor term of τ.
    pub tau_actor: Joints,
    /// −K2 Z2 term of τ.
    pub tau_feedback: Joints,
    /// Barrier term of τ.
    pub tau_barrier: Joints,
    /// ‖Ŵ_a‖ per joint before the update.
    pub wa_norm: Joints,
}

/// Timing of one plant cycle (published by the plant, which is the clock).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("testbed.Timing.v1")]
pub struct Timing {
    /// seq = cycle k, t_ns = t_k.
    pub header: Header,
    /// How late the plant woke after its deadline, ns (real time; 0 in lockstep).
    pub wake_late_ns: i64,
    /// Wall time since the previous cycle's wake-up, ns (0 at k = 0).
    pub period_ns: i64,
    /// State k−1 published → its command sent, ns; −1 if it never came.
    pub round_trip_ns: i64,
    /// Controller compute time for step k−1, ns; −1 if unknown.
    pub controller_compute_ns: i64,
    /// 1 if the command for step k−1 had not arrived at this cycle's deadline.
    pub deadline_missed: u32,
    /// Padding.
    pub reserved: u32,
    /// Deadline misses so far.
    pub deadline_misses: u64,
}

/// [`Control::command`]: start the run at `epoch_wall_ns`.
pub const CONTROL_START: u32 = 1;
/// [`Control::command`]: stop and exit.
pub const CONTROL_STOP: u32 = 2;

/// From the launcher to every node.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("testbed.Control.v1")]
pub struct Control {
    /// seq counts control messages.
    pub header: Header,
    /// [`CONTROL_START`] or [`CONTROL_STOP`].
    pub command: u32,
    /// Padding.
    pub reserved: u32,
    /// CLOCK_MONOTONIC time of step 0, ns (with START).
    pub epoch_wall_ns: u64,
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

/// From every node to the launcher.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("testbed.NodeStatus.v1")]
pub struct NodeStatus {
    /// seq counts this node's status messages.
    pub header: Header,
    /// [`NodeKind`] as u32.
    pub node: u32,
    /// NODE_READY, NODE_RUNNING, NODE_DONE or NODE_FAILED.
    pub state: u32,
    /// The node's process id.
    pub pid: u32,
    /// Padding.
    pub reserved: u32,
    /// Steps the node has handled.
    pub step: u64,
}
