//! The torque bounds of `cbf-ctc` and `mpc` (BASELINES §3), mapped onto
//! the error accelerations they command. With τ = M(q)(q̈_d + u) + h(q, q̇)
//! the limits |τ_i| ≤ τ̄_i are a polytope in u that couples the joints;
//! both laws act joint by joint, so they take a box inside it instead:
//! |u_k| ≤ a_k = s d_k with d_k = τ̄_k / M_kk (what joint k's own motor
//! could do alone) and the largest s for which every row holds,
//!
//!   |τ_i| ≤ |τ0_i| + Σ_k |M_ik| a_k ≤ τ̄_i,   τ0 = M q̈_d + h,
//!
//! so every u in the box gives torques within the limits (sound), at the
//! price of the box's corners being the only points that reach them
//! (conservative). Where the feedforward τ0 alone exceeds a limit, no box
//! around u = 0 exists and the box is the point u = 0.

use arm_model::ArmModel;
use arm_model::dynamics::Dynamics;

/// The box's half-widths a per joint, recomputed every step.
#[derive(Debug)]
pub(crate) struct TorqueBox {
    /// τ̄ per controlled joint.
    effort: Vec<f64>,
    /// Scratch: M(q), row-major.
    m: Vec<f64>,
    /// Scratch: a unit acceleration and zero velocity.
    unit: Vec<f64>,
    zero: Vec<f64>,
    /// The half-widths a.
    a: Vec<f64>,
}

impl TorqueBox {
    /// The box for `model`'s controlled joints, if every one has an effort
    /// limit (a joint without one would make every other joint's share
    /// depend on an infinite number: no bound is the honest answer).
    pub(crate) fn new(model: &ArmModel) -> Option<Self> {
        let effort: Option<Vec<f64>> = model
            .actuated
            .iter()
            .map(|&j| model.joints.get(j).and_then(|j| j.effort))
            .collect();
        let effort = effort?;
        let n = effort.len();
        Some(Self {
            effort,
            m: vec![0.0; n * n],
            unit: vec![0.0; n],
            zero: vec![0.0; n],
            a: vec![0.0; n],
        })
    }

    /// The half-widths at this step's q, q̇, q̈_d: n + 2 passes of the
    /// model's inverse dynamics (M's columns as τ(q, 0, e_k) − G(q), and
    /// τ0 = τ(q, q̇, q̈_d)).
    pub(crate) fn update(&mut self, d: &mut Dynamics, q: &[f64], qd: &[f64], qdd_d: &[f64]) {
        let n = self.effort.len();
        let g = d.gravity(q).to_vec();
        for k in 0..n {
            self.unit.fill(0.0);
            self.unit[k] = 1.0;
            let col = d.inverse(q, &self.zero, &self.unit);
            for i in 0..n {
                self.m[i * n + k] = col[i] - g[i];
            }
        }
        let tau0 = d.inverse(q, qd, qdd_d);
        let share = |k: usize| {
            let mkk = self.m[k * n + k];
            match self.effort[k] / mkk {
                x if x.is_finite() && x > 0.0 => x,
                _ => 0.0,
            }
        };
        let mut s = f64::INFINITY;
        for (i, &t0) in tau0.iter().enumerate().take(n) {
            let room = (self.effort[i] - t0.abs()).max(0.0);
            let used: f64 = (0..n).map(|k| self.m[i * n + k].abs() * share(k)).sum();
            if used > 0.0 {
                s = s.min(room / used);
            }
        }
        // s ≤ 1 whenever a row has M_ii > 0 (its own share alone is τ̄_i);
        // a NaN (a non-finite state) gives no authority, not an infinite one.
        let s = if s.is_finite() { s.max(0.0) } else { 0.0 };
        for k in 0..n {
            self.a[k] = s * share(k);
        }
    }

    /// The half-widths of the last [`TorqueBox::update`].
    pub(crate) fn half_widths(&self) -> &[f64] {
        &self.a
    }
}
