//! One control step as the summary and the CSV see it.

/// Row k of a run: the state at t_k, the reference, and the torque applied
/// over [t_k, t_k + Δt]. Per-joint slices have one entry per joint.
#[derive(Debug, Clone, Copy)]
pub struct StepRecord<'a> {
    /// Sim time t_k, s.
    pub t: f64,
    /// Joint positions q(t_k).
    pub q: &'a [f64],
    /// Joint velocities q̇(t_k).
    pub qd: &'a [f64],
    /// The plant's mean acceleration over the step, (q̇(t_k+1) − q̇(t_k)) / Δt.
    pub qdd: &'a [f64],
    /// Torque applied over the step.
    pub tau: &'a [f64],
    /// Desired position q_d(t_k).
    pub q_d: &'a [f64],
    /// Desired velocity q̇_d(t_k).
    pub qd_d: &'a [f64],
    /// Envelope k_c(t_k) per joint, as the trajectory gives it.
    pub kc: &'a [f64],
    /// Tracking error Z1.
    pub z1: &'a [f64],
    /// Shifted error Z1γ.
    pub z1g: &'a [f64],
    /// Z2 = q̇ − α.
    pub z2: &'a [f64],
    /// ‖Ŵ_a‖ per joint (before this step's update).
    pub wa_norm: &'a [f64],
    /// The controller's guard clamped D.
    pub barrier_breached: bool,
    /// The controller published zero torque because of a fault.
    pub fault: bool,
}
