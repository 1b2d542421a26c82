//! Low-complexity prescribed performance control (Bechlioulis & Rovithakis,
//! Automatica 50, 2014), as BASELINES.md writes it: funnels that close onto
//! the run's envelope k_c by about T_c, so that it competes with the
//! deferred constraint on the same task.

use crate::nac::{begin_plain_step, end_plain_step};
use crate::{ControllerError, ControllerInput, ControllerParams, Diagnostics, Tuning};

/// ξ is clamped to ±(1 − this) where the law is undefined (|ξ| ≥ 1).
pub const XI_LIMIT: f64 = 1e-6;

/// The funnel law for n joints.
#[derive(Debug, Clone)]
pub struct Ppc {
    n: usize,
    k1: Vec<f64>,
    k2: Vec<f64>,
    /// Decay rate l = 3 / T_c.
    l: f64,
    rho2_inf: f64,
    /// Matched tuning: k1 is scaled by k_c(0) / 2 at the first step.
    tuning: Tuning,
    /// Time and funnel starts of the first step: (t0, ρ1,0, ρ2,0) per joint.
    start: Option<(f64, Vec<f64>, Vec<f64>)>,
}

impl Ppc {
    /// With k1 = K1, k2 = K2 and `params.rho2_inf`; matched (near e = 0,
    /// ε ≈ 2 ξ, so the law is `pd` with K1_eff = 2 k1 / ρ1 and
    /// K2_eff = 2 k2 / ρ2): k1 = K1 k_c(0) / 2 and k2 = K2 ρ2,∞ / 2.
    pub fn new(params: &ControllerParams, dof: usize) -> Result<Self, ControllerError> {
        let mut k2 = params.k2.resolve("controller.k2", dof)?;
        if params.tuning == Tuning::Matched {
            k2.iter_mut().for_each(|k| *k *= params.rho2_inf / 2.0);
        }
        Ok(Self {
            n: dof,
            k1: params.k1.resolve("controller.k1", dof)?,
            k2,
            l: 3.0 / params.tc,
            rho2_inf: params.rho2_inf,
            tuning: params.tuning,
            start: None,
        })
    }

    /// One step. The position funnel ρ1 goes in `out.kc`, ρ1² − e² in
    /// `out.d`, and a clamped ξ sets `out.barrier_breached` (a funnel breach).
    pub fn step(&mut self, input: &ControllerInput<'_>, out: &mut Diagnostics) {
        if !begin_plain_step(input, self.n, out) {
            return;
        }
        if self.start.is_none() && self.tuning == Tuning::Matched {
            // ρ1,∞ = k_c: the funnel's final width, taken at the first step.
            for (k, kc) in self.k1.iter_mut().zip(input.kc) {
                *k *= kc / 2.0;
            }
        }
        let (t0, rho1_0, rho2_0) = self.start.get_or_insert_with(|| {
            let rho1_0: Vec<f64> = (0..input.q.len())
                .map(|i| (input.q[i] - input.q_d[i]).abs() + input.kc[i])
                .collect();
            (input.t, rho1_0, Vec::new())
        });
        let decay = (-self.l * (input.t - *t0)).exp();
        let mut breached = false;
        for i in 0..self.n {
            let e = input.q[i] - input.q_d[i];
            let kc = input.kc[i];
            let rho1 = (rho1_0[i] - kc) * decay + kc;
            let eps1 = transformed(e / rho1, &mut breached);
            let alpha = input.qd_d[i] - self.k1[i] * eps1;
            let z2 = input.qd[i] - alpha;
            // ρ2,0 = 2 |q̇(0) − α(0)| + ρ2,∞, fixed at the first step.
            if rho2_0.len() <= i {
                rho2_0.push(2.0 * z2.abs() + self.rho2_inf);
            }
            let rho2 = (rho2_0[i] - self.rho2_inf) * decay + self.rho2_inf;
            let eps2 = transformed(z2 / rho2, &mut breached);
            out.z1[i] = e;
            out.z1g[i] = e;
            out.alpha[i] = alpha;
            out.z2[i] = z2;
            out.kc[i] = rho1;
            out.d[i] = rho1 * rho1 - e * e;
            out.tau_feedback[i] = -self.k2[i] * eps2;
            out.tau[i] = out.tau_feedback[i];
            out.tau_actor[i] = 0.0;
            out.tau_barrier[i] = 0.0;
            out.tau_model[i] = 0.0;
            out.wa_norm[i] = 0.0;
        }
        out.barrier_breached = breached;
        end_plain_step(out);
    }
}

/// ε = ln((1 + ξ) / (1 − ξ)), with ξ clamped to ±(1 − [`XI_LIMIT`]) where
/// the law is undefined; a clamp sets `breached`.
fn transformed(xi: f64, breached: &mut bool) -> f64 {
    let lim = 1.0 - XI_LIMIT;
    let xi = if xi.abs() >= lim {
        *breached = true;
        lim.copysign(xi)
    } else {
        xi
    };
    ((1.0 + xi) / (1.0 - xi)).ln()
}

#[cfg(test)]
#[path = "ppc_tests.rs"]
mod tests;
