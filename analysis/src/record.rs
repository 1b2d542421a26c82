//! One control step as the summary and the CSV see it.

/// Row k of a run: the state at t_k, the reference, and the torque applied
/// over [t_k, t_k + Δt]. Per-joint slices have one entry per joint.
#[derive(Debug, Clone, Copy)]
pub struct StepRecord<'a> {
    /// Sim time t_k, s.
    pub t: f64,
    /// True joint positions q(t_k).
    pub q: &'a [f64],
    /// True joint velocities q̇(t_k).
    pub qd: &'a [f64],
    /// Positions as the sensors reported them (what the controller used).
    pub q_measured: &'a [f64],
    /// Velocities as the sensors reported them.
    pub qd_measured: &'a [f64],
    /// The plant's mean acceleration over the step, (q̇(t_k+1) − q̇(t_k)) / Δt.
    pub qdd: &'a [f64],
    /// Motor torque applied over the step (after delay, loss, saturation).
    pub tau: &'a [f64],
    /// Disturbance d applied over the step.
    pub disturbance: &'a [f64],
    /// Plant effects over the step (bits of `wire::Effects`).
    pub effects: u32,
    /// Desired position q_d(t_k).
    pub q_d: &'a [f64],
    /// Desired velocity q̇_d(t_k).
    pub qd_d: &'a [f64],
    /// Envelope k_c(t_k) per joint, as the trajectory gives it.
    pub kc: &'a [f64],
    /// Tracking error Z1 as the controller saw it (from measured q).
    pub z1: &'a [f64],
    /// Shifted error Z1γ.
    pub z1g: &'a [f64],
    /// Z2 = q̇ − α.
    pub z2: &'a [f64],
    /// ‖Ŵ_a‖ per joint (before this step's update).
    pub wa_norm: &'a [f64],
    /// The actor's part of the commanded torque (zero for laws without one).
    pub tau_actor: &'a [f64],
    /// The controller's guard clamped D.
    pub barrier_breached: bool,
    /// The controller published zero torque because of a fault.
    pub fault: bool,
    /// An external controller's own diagnostics of the step, in its
    /// declared order (empty when it declared none).
    pub own: &'a [f64],
}
