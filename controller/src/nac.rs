//! One control step of the paper's law (SPEC §4–§10), and of its ablations
//! and the classic barrier law (BASELINES.md), which switch parts of it off.

use crate::law_table::LawKind;
use crate::params::{BarrierMode, ControllerParams, Integrator};
use crate::rbf::Rbf;
use crate::shifting::shifting;
use crate::weight_update::{advance_euler, advance_exact};
use crate::{ControllerError, Diagnostics, Fault};

/// What the controller reads at step k: the joint state and the reference
/// at the state's sim time.
#[derive(Debug, Clone, Copy)]
pub struct ControllerInput<'a> {
    /// Sim time stamped on the joint state, s.
    pub t: f64,
    /// Joint positions q.
    pub q: &'a [f64],
    /// Joint velocities q̇.
    pub qd: &'a [f64],
    /// Desired positions q_d(t).
    pub q_d: &'a [f64],
    /// Desired velocities q̇_d(t).
    pub qd_d: &'a [f64],
    /// Desired accelerations q̈_d(t) (only `ctc` uses them).
    pub qdd_d: &'a [f64],
    /// Envelope k_c(t) (> 0).
    pub kc: &'a [f64],
    /// Envelope rate k̇_c(t).
    pub kc_dot: &'a [f64],
}

/// Which parts of the paper's law are on (BASELINES.md: its ablations and
/// `blf` are the same law with parts switched off).
#[derive(Debug, Clone, Copy)]
struct Parts {
    /// γ(t) from SPEC §4; off: γ ≡ 1, γ̇ ≡ 0.
    shift: bool,
    /// The actor and the critic; off: actor output ≡ 0, no updates.
    networks: bool,
    /// The critic; off: Ĵ ≡ 0, critic not updated.
    critic: bool,
    /// The barrier's β (1 for `blf`).
    beta: f64,
}

impl Parts {
    fn of(p: &ControllerParams) -> Result<Self, ControllerError> {
        match p.law.kind() {
            LawKind::Barrier(b) => Ok(Parts {
                shift: b.shift,
                networks: b.networks,
                critic: b.critic,
                beta: if b.classic_barrier { 1.0 } else { p.beta },
            }),
            LawKind::Feedback(_) | LawKind::Ppc => Err(ControllerError::InvalidParameter {
                key: "controller.law".into(),
                value: p.law.to_string(),
                need: "the paper's law, an ablation of it, or blf".into(),
            }),
        }
    }
}

/// The controller: parameters, the two networks and their weights.
#[derive(Debug, Clone)]
pub struct Controller {
    p: ControllerParams,
    parts: Parts,
    n: usize,
    /// K1_i and K2_i resolved for the n joints.
    k1: Vec<f64>,
    k2: Vec<f64>,
    actor: Rbf,
    critic: Rbf,
    /// Ŵ_a, N×n, column-major: column j (joint j) is `wa[j*N..(j+1)*N]`.
    wa: Vec<f64>,
    /// Ŵ_c, length N.
    wc: Vec<f64>,
    /// Z_c and t of the previous good step, for Ż_c.
    prev_zc: Vec<f64>,
    prev_t: Option<f64>,
    // Scratch, allocated once.
    za: Vec<f64>,
    zc: Vec<f64>,
    zc_dot: Vec<f64>,
    sa: Vec<f64>,
    sc: Vec<f64>,
    lambda: Vec<f64>,
}

impl Controller {
    /// A controller for `dof` joints with zero initial weights.
    pub fn new(params: ControllerParams, dof: usize) -> Result<Self, ControllerError> {
        params.validate()?;
        if dof == 0 {
            return Err(ControllerError::NoJoints);
        }
        let parts = Parts::of(&params)?;
        let p = &params;
        let rbf = |dim| {
            Rbf::new(
                p.rbf_layout,
                p.neurons,
                dim,
                p.center_min,
                p.center_max,
                p.width,
            )
        };
        let (actor, critic) = (rbf(4 * dof), rbf(2 * dof));
        let (na, nc) = (actor.len(), critic.len());
        let k1 = params.k1.resolve("controller.k1", dof)?;
        let k2 = params.k2.resolve("controller.k2", dof)?;
        Ok(Self {
            k1,
            k2,
            actor,
            critic,
            parts,
            n: dof,
            wa: vec![0.0; na * dof],
            wc: vec![0.0; nc],
            prev_zc: vec![0.0; 2 * dof],
            prev_t: None,
            za: vec![0.0; 4 * dof],
            zc: vec![0.0; 2 * dof],
            zc_dot: vec![0.0; 2 * dof],
            sa: vec![0.0; na],
            sc: vec![0.0; nc],
            lambda: vec![0.0; nc],
            p: params,
        })
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.n
    }

    /// The parameters in use.
    pub fn params(&self) -> &ControllerParams {
        &self.p
    }

    /// Actor weights Ŵ_a (features × n, column-major).
    pub fn actor_weights(&self) -> &[f64] {
        &self.wa
    }

    /// Critic weights Ŵ_c.
    pub fn critic_weights(&self) -> &[f64] {
        &self.wc
    }

    /// A diagnostics buffer sized for this controller.
    pub fn diagnostics(&self) -> Diagnostics {
        Diagnostics::new(self.n)
    }

    /// One control step: computes τ (in `out.tau`) and every quantity of
    /// SPEC §12 into `out`, then advances the weights over `dt` seconds.
    ///
    /// Never panics on bad numbers: a non-finite input or output gives zero
    /// torque, sets `out.fault` and skips the weight update (SPEC §10).
    pub fn step(&mut self, dt: f64, input: &ControllerInput<'_>, out: &mut Diagnostics) {
        let n = self.n;
        out.t = input.t;
        out.fault = None;
        out.barrier_breached = false;
        if let Some(fault) = check_input(input, n) {
            publish_fault(out, fault);
            return;
        }
        self.errors_and_barrier(input, out);
        self.torque(input, out);
        self.critic_signals(input, out);
        let finite_out = out.tau.iter().all(|x| x.is_finite())
            && out.r.is_finite()
            && out.delta.is_finite()
            && self.lambda.iter().all(|x| x.is_finite());
        if !finite_out {
            publish_fault(out, Fault::NonFiniteOutput);
            return;
        }

        self.advance_weights(dt, out);
    }

    /// γ, Z1, Z1γ, the barrier's D, α, Z2 and the barrier torque (SPEC §4–§7).
    fn errors_and_barrier(&mut self, input: &ControllerInput<'_>, out: &mut Diagnostics) {
        let n = self.n;
        let p = &self.p;
        let beta = self.parts.beta;
        let (gamma, gamma_dot) = if self.parts.shift {
            shifting(input.t, p.tc)
        } else {
            (1.0, 0.0)
        };
        out.gamma = gamma;
        out.gamma_dot = gamma_dot;

        for i in 0..n {
            out.z1[i] = input.q[i] - input.q_d[i];
            out.z1g[i] = gamma * out.z1[i];
        }

        // The bound each joint sees, its rate, and ‖Z1‖² as SPEC §5 defines them.
        let (norm_kc, norm_kc_dot) = match p.barrier {
            BarrierMode::PerJoint => (0.0, 0.0),
            BarrierMode::Norm => {
                let mut m = 0;
                for i in 1..n {
                    if input.kc[i] < input.kc[m] {
                        m = i;
                    }
                }
                (input.kc[m], input.kc_dot[m])
            }
        };
        let z1_sq_all: f64 = out.z1.iter().map(|z| z * z).sum();
        let z1g_sq_all: f64 = out.z1g.iter().map(|z| z * z).sum();

        for i in 0..n {
            let (kc, kc_dot, z1_sq, z1g_sq) = match p.barrier {
                BarrierMode::PerJoint => (
                    input.kc[i],
                    input.kc_dot[i],
                    out.z1[i] * out.z1[i],
                    out.z1g[i] * out.z1g[i],
                ),
                BarrierMode::Norm => (norm_kc, norm_kc_dot, z1_sq_all, z1g_sq_all),
            };
            let d_raw = kc * kc - z1g_sq;
            let d_min = p.breach_epsilon * kc * kc;
            let d = if d_raw < d_min {
                out.barrier_breached = true;
                d_min
            } else {
                d_raw
            };
            out.kc[i] = kc;
            out.d[i] = d_raw;
            let z1 = out.z1[i];
            out.alpha[i] = -self.k1[i] * z1 - p.a * gamma_dot * gamma_dot * z1 * z1_sq / (beta * d)
                + input.qd_d[i]
                + (kc_dot / kc) * z1;
            out.z2[i] = input.qd[i] - out.alpha[i];
            out.tau_barrier[i] = -gamma * out.z1g[i] / (beta * d);
        }
    }

    /// The networks' features and τ = actor − K2 Z2 + barrier (SPEC §7, §8).
    fn torque(&mut self, input: &ControllerInput<'_>, out: &mut Diagnostics) {
        let n = self.n;
        // Actor input Z_a = [q; q̇; Z1; Z2], critic input Z_c = [Z1; Z2].
        self.za[..n].copy_from_slice(input.q);
        self.za[n..2 * n].copy_from_slice(input.qd);
        self.za[2 * n..3 * n].copy_from_slice(&out.z1);
        self.za[3 * n..].copy_from_slice(&out.z2);
        self.zc[..n].copy_from_slice(&out.z1);
        self.zc[n..].copy_from_slice(&out.z2);
        // Switched-off networks keep S = 0, so their outputs are 0.
        if self.parts.networks {
            self.actor.features(&self.za, &mut self.sa);
        }
        if self.parts.critic {
            self.critic.features(&self.zc, &mut self.sc);
        }

        let nn = self.sa.len();
        for j in 0..n {
            let col = &self.wa[j * nn..(j + 1) * nn];
            out.tau_actor[j] = dot(col, &self.sa);
            out.tau_feedback[j] = -self.k2[j] * out.z2[j];
            out.tau_model[j] = 0.0;
            out.tau[j] = out.tau_actor[j] + out.tau_feedback[j] + out.tau_barrier[j];
            out.wa_norm[j] = dot(col, col).sqrt();
        }
        out.wc_norm = dot(&self.wc, &self.wc).sqrt();
        out.j_hat = dot(&self.wc, &self.sc);
    }

    /// r, Ż_c, Λ and δ of the critic (SPEC §8).
    fn critic_signals(&mut self, input: &ControllerInput<'_>, out: &mut Diagnostics) {
        let p = &self.p;
        out.r = p.q_weight * dot(&self.zc, &self.zc) + p.r_weight * dot(&out.tau, &out.tau);
        if !self.parts.critic {
            // Ŵ_c stays 0, so δ = r whatever Λ is.
            out.delta = out.r;
            return;
        }
        match self.prev_t {
            Some(t0) if input.t > t0 => {
                let h = input.t - t0;
                for ((d, z), z0) in self.zc_dot.iter_mut().zip(&self.zc).zip(&self.prev_zc) {
                    *d = (z - z0) / h;
                }
            }
            _ => self.zc_dot.iter_mut().for_each(|d| *d = 0.0),
        }
        self.critic
            .directional_derivative(&self.zc, &self.zc_dot, &self.sc, &mut self.lambda);
        for (l, s) in self.lambda.iter_mut().zip(&self.sc) {
            *l -= s / p.psi;
        }
        out.delta = out.r + dot(&self.wc, &self.lambda);
    }

    /// Both weight sets over `dt` with this step's signals held (SPEC §9).
    fn advance_weights(&mut self, dt: f64, out: &Diagnostics) {
        let n = self.n;
        let p = &self.p;
        let nn = self.sa.len();
        let advance: fn(&mut [f64], &[f64], f64, f64, f64, f64) = match p.integrator {
            Integrator::Exact => advance_exact,
            Integrator::Euler => advance_euler,
        };
        self.prev_zc.copy_from_slice(&self.zc);
        self.prev_t = Some(out.t);
        if self.parts.critic {
            advance(&mut self.wc, &self.lambda, out.r, p.sigma_c, p.eta_c, dt);
        }
        if !self.parts.networks {
            return;
        }
        for j in 0..n {
            let c = out.z2[j] / p.sigma_a + p.k_a * out.j_hat;
            let col = &mut self.wa[j * nn..(j + 1) * nn];
            advance(col, &self.sa, c, p.sigma_a, p.eta_a, dt);
        }
    }
}

/// The start of a step of a law with no shift and no networks (the
/// baselines): resets the flags and checks the input (false: a fault was
/// published, stop here); γ = 1, γ̇ = 0, as the constraint is simply on.
pub(crate) fn begin_plain_step(
    input: &ControllerInput<'_>,
    n: usize,
    out: &mut Diagnostics,
) -> bool {
    out.t = input.t;
    out.fault = None;
    out.barrier_breached = false;
    if let Some(fault) = check_input(input, n) {
        publish_fault(out, fault);
        return false;
    }
    out.gamma = 1.0;
    out.gamma_dot = 0.0;
    true
}

/// The end of such a step: no critic, and a non-finite torque becomes a fault.
pub(crate) fn end_plain_step(out: &mut Diagnostics) {
    (out.j_hat, out.delta, out.r, out.wc_norm) = (0.0, 0.0, 0.0, 0.0);
    if out.tau.iter().any(|x| !x.is_finite()) {
        publish_fault(out, Fault::NonFiniteOutput);
    }
}

/// A step that publishes zero torque because of `fault` (SPEC §10).
pub(crate) fn publish_fault(out: &mut Diagnostics, fault: Fault) {
    out.fault = Some(fault);
    out.tau.iter_mut().for_each(|x| *x = 0.0);
}

pub(crate) fn check_input(input: &ControllerInput<'_>, n: usize) -> Option<Fault> {
    let slices = [
        input.q,
        input.qd,
        input.q_d,
        input.qd_d,
        input.qdd_d,
        input.kc,
        input.kc_dot,
    ];
    if slices.iter().any(|s| s.len() != n) {
        return Some(Fault::WrongLength);
    }
    let finite = input.t.is_finite() && slices.iter().all(|s| s.iter().all(|x| x.is_finite()));
    if !finite {
        return Some(Fault::NonFiniteInput);
    }
    if input.kc.iter().any(|&k| k <= 0.0) {
        return Some(Fault::EnvelopeNotPositive);
    }
    None
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The barrier Lyapunov function V1 of eq. (v1) for the errors `z1g` and
/// bounds `kc` in the given mode; +∞ once an error reaches its bound.
pub fn barrier_lyapunov(z1g: &[f64], kc: &[f64], beta: f64, mode: BarrierMode) -> f64 {
    let term = |k: f64, z2: f64| {
        let d = k * k - z2;
        if d > 0.0 {
            (k * k / d).ln() / (2.0 * beta)
        } else {
            f64::INFINITY
        }
    };
    match mode {
        BarrierMode::PerJoint => z1g.iter().zip(kc).map(|(z, k)| term(*k, z * z)).sum(),
        BarrierMode::Norm => {
            let k = kc.iter().copied().fold(f64::INFINITY, f64::min);
            term(k, z1g.iter().map(|z| z * z).sum())
        }
    }
}

#[cfg(test)]
#[path = "nac_tests.rs"]
mod tests;
