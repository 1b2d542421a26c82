//! The unconstrained reference laws of BASELINES.md: `pd`, sliding mode
//! `smc`, and the model-based `pd-gravity` and `ctc`, with gains matched to
//! the paper's K1, K2 so that a difference in a comparison comes from the
//! structure.

use arm_model::ArmModel;
use arm_model::dynamics::Dynamics;

use crate::law_table::FeedbackKind;
use crate::mpc::{ErrorMpc, MpcInput, MpcShape, Weights};
use crate::nac::{begin_plain_step, end_plain_step};
use crate::torque_box::TorqueBox;
use crate::{ControllerError, ControllerInput, ControllerParams, Diagnostics, Tuning};

/// `pd`, `smc`, `pd-gravity`, `ctc`, `cbf-ctc` or `mpc` for n joints.
#[derive(Debug)]
pub struct Feedback {
    kind: FeedbackKind,
    n: usize,
    k1: Vec<f64>,
    k2: Vec<f64>,
    /// `ctc`'s K_p', K_d' per joint; with matched tuning, set at the first
    /// step (they need the first reference posture).
    ctc_gains: Option<(Vec<f64>, Vec<f64>)>,
    /// The law's copy of the arm's model (model-based laws only).
    model: Option<Dynamics>,
    /// Scratch: q̈_d − K_d' ė − K_p' e for `ctc`.
    v: Vec<f64>,
    /// `smc`'s switching gain k_s and boundary layer φ.
    smc: (f64, f64),
    /// `cbf-ctc`: T_c (the filter acts from then on), the rate λ and the
    /// robust margin δ.
    cbf: (f64, f64, f64),
    /// `mpc`: how its QP is posed; the QP, built at the first step from
    /// `ctc_gains`.
    mpc: MpcShape,
    qp: Option<Box<ErrorMpc>>,
    /// `cbf-ctc`, `mpc`: the torque bounds as a box on u (`torque_bounds`
    /// and every joint with an effort limit).
    torque_box: Option<TorqueBox>,
    /// Scratch for `mpc`: e and ė.
    e: Vec<f64>,
    ed: Vec<f64>,
}

impl Feedback {
    /// The law `kind` (`params.law`'s); the model-based ones evaluate
    /// `model`, scaled by `params.model_scale`.
    pub fn new(
        params: &ControllerParams,
        kind: FeedbackKind,
        dof: usize,
        model: Option<&ArmModel>,
    ) -> Result<Self, ControllerError> {
        let law = params.law;
        let model = match (law.model_based(), model) {
            (false, _) => None,
            (true, Some(m)) if m.dof() == dof => Some(m),
            (true, Some(m)) => {
                return Err(ControllerError::InvalidParameter {
                    key: "controller.law".into(),
                    value: format!("{law} with a model of {} joints", m.dof()),
                    need: format!("a model of the {dof} controlled joints"),
                });
            }
            (true, None) => return Err(ControllerError::NeedsModel(law)),
        };
        let torque_box = match (kind, params.torque_bounds) {
            (FeedbackKind::CbfCtc | FeedbackKind::Mpc, true) => model.and_then(TorqueBox::new),
            _ => None,
        };
        let model = model.map(|m| Dynamics::new(m, params.model_scale));
        let k1 = params.k1.resolve("controller.k1", dof)?;
        let k2 = params.k2.resolve("controller.k2", dof)?;
        let ctc_gains = match params.tuning {
            Tuning::AsGiven => Some((
                k1.iter().zip(&k2).map(|(a, b)| a * b).collect(),
                k1.iter().zip(&k2).map(|(a, b)| a + b).collect(),
            )),
            Tuning::Matched => None,
        };
        Ok(Self {
            kind,
            n: dof,
            k1,
            k2,
            ctc_gains,
            model,
            v: vec![0.0; dof],
            smc: (params.smc_gain, params.smc_boundary),
            cbf: (params.tc, params.cbf_rate, params.cbf_margin),
            mpc: MpcShape {
                horizon: params.mpc_horizon,
                h: params.mpc_step,
                tc: params.tc,
                bounded: torque_box.is_some(),
                disturbance: params.mpc_disturbance,
            },
            qp: None,
            torque_box,
            e: vec![0.0; dof],
            ed: vec![0.0; dof],
        })
    }

    /// One step: τ into `out.tau` and the errors into `out`.
    pub fn step(&mut self, input: &ControllerInput<'_>, out: &mut Diagnostics) {
        if !begin_plain_step(input, self.n, out) {
            return;
        }
        let computed_torque = matches!(
            self.kind,
            FeedbackKind::Ctc | FeedbackKind::CbfCtc | FeedbackKind::Mpc
        );
        if computed_torque && self.ctc_gains.is_none() {
            self.ctc_gains = Some(self.matched_ctc_gains(input.q_d));
        }
        for i in 0..self.n {
            let e = input.q[i] - input.q_d[i];
            let ed = input.qd[i] - input.qd_d[i];
            out.z1[i] = e;
            out.z1g[i] = e;
            out.alpha[i] = input.qd_d[i];
            out.z2[i] = ed;
            out.kc[i] = input.kc[i];
            out.d[i] = input.kc[i] * input.kc[i] - e * e;
            out.tau_actor[i] = 0.0;
            out.tau_barrier[i] = 0.0;
            out.wa_norm[i] = 0.0;
            // K_p = K1 K2, K_d = K2 (pd); ctc's K_p', K_d' from `ctc_gains`.
            let (k1, k2) = (self.k1[i], self.k2[i]);
            match (self.kind, &self.ctc_gains) {
                (FeedbackKind::Ctc | FeedbackKind::CbfCtc, Some((kp, kd))) => {
                    self.v[i] = input.qdd_d[i] - kd[i] * ed - kp[i] * e
                }
                // Unreachable: the gains are set above.
                (FeedbackKind::Ctc | FeedbackKind::CbfCtc, None) => self.v[i] = 0.0,
                // v comes from the QP below.
                (FeedbackKind::Mpc, _) => (self.e[i], self.ed[i]) = (e, ed),
                (FeedbackKind::Pd | FeedbackKind::PdGravity, _) => {
                    out.tau_feedback[i] = -k1 * k2 * e - k2 * ed
                }
                // s = ė + K1 e; τ = −K2 s − k_s sat(s / φ) (BASELINES §2).
                (FeedbackKind::Smc, _) => {
                    let (ks, phi) = self.smc;
                    let s = ed + k1 * e;
                    out.alpha[i] = input.qd_d[i] - k1 * e;
                    out.z2[i] = s;
                    out.tau_feedback[i] = -k2 * s - ks * (s / phi).clamp(-1.0, 1.0)
                }
            }
        }
        if let (Some(b), Some(m)) = (self.torque_box.as_mut(), self.model.as_mut()) {
            b.update(m, input.q, input.qd, input.qdd_d);
        }
        if self.kind == FeedbackKind::CbfCtc && input.t >= self.cbf.0 {
            // The filter clipping is the law's guard acting: a breach step.
            out.barrier_breached = self.cbf_filter(input);
        }
        if self.kind == FeedbackKind::Mpc {
            match self.mpc_inputs(input) {
                Some(breached) => out.barrier_breached = breached,
                // No finite torque: the step's end publishes the fault.
                None => self.v.iter_mut().for_each(|v| *v = f64::NAN),
            }
        }
        self.model_terms(input, out);
        end_plain_step(out);
    }

    /// The CBF–QP safety filter (BASELINES §3) on `ctc`'s commanded
    /// accelerations: with u_i = v_i − q̈_d,i = ë_i and h_i = k_c,i² − e_i²,
    /// min Σ (u_i − u_nom,i)² subject to ḧ_i + 2λ ḣ_i + λ² h_i ≥ 0 for the
    /// worst error-acceleration disturbance |d_i| ≤ δ, i.e.
    /// 2 e_i u_i + 2|e_i| δ ≤ b_i = 2k̇_c,i² − 2ė_i² + 2λ ḣ_i + λ² h_i (k̈_c
    /// taken as 0: the reference sample carries k_c and k̇_c only), and,
    /// with torque bounds, |u_i| ≤ a_i. The QP separates per joint: each
    /// joint's u is the nominal one projected onto an interval (see
    /// [`cbf_interval`]). Returns whether the CBF row bound or could not be
    /// met within the input bound on any joint (clipping by the torque box
    /// alone is no breach).
    fn cbf_filter(&mut self, input: &ControllerInput<'_>) -> bool {
        let (_, lambda, margin) = self.cbf;
        let a = self.torque_box.as_ref().map(TorqueBox::half_widths);
        let mut clipped = false;
        for i in 0..self.n {
            let e = input.q[i] - input.q_d[i];
            let ed = input.qd[i] - input.qd_d[i];
            let (k, kd) = (input.kc[i], input.kc_dot[i]);
            let h = k * k - e * e;
            let hd = 2.0 * k * kd - 2.0 * e * ed;
            let b = 2.0 * kd * kd - 2.0 * ed * ed + 2.0 * lambda * hd + lambda * lambda * h
                - 2.0 * e.abs() * margin;
            let u_nom = self.v[i] - input.qdd_d[i];
            let bound = a.map_or(f64::INFINITY, |a| a[i]);
            let (u, binds) = cbf_interval(e, b, bound, u_nom);
            clipped |= binds;
            self.v[i] = input.qdd_d[i] + u;
        }
        clipped
    }

    /// `mpc` (BASELINES §4): v = q̈_d + u with u the QP's first input per
    /// joint; the QP is built at the first step, when `ctc`'s gains (and
    /// so its weights) are known. Returns whether the envelope could not
    /// be held, or None if the QP cannot be built (a Riccati equation that
    /// does not settle: the law cannot give a finite torque).
    fn mpc_inputs(&mut self, input: &ControllerInput<'_>) -> Option<bool> {
        if self.qp.is_none() {
            let (kp, kd) = self.ctc_gains.as_ref()?;
            let weights: Vec<Weights> = kp
                .iter()
                .zip(kd)
                .map(|(&p, &d)| Weights::matching(p, d))
                .collect();
            self.qp = Some(Box::new(ErrorMpc::new(&weights, self.mpc).ok()?));
        }
        let qp = self.qp.as_mut()?;
        let (u, breached) = qp.solve(&MpcInput {
            t: input.t,
            e: &self.e,
            ed: &self.ed,
            kc: input.kc,
            kc_dot: input.kc_dot,
            u_max: self.torque_box.as_ref().map(TorqueBox::half_widths),
        });
        for ((v, a), u) in self.v.iter_mut().zip(input.qdd_d).zip(u) {
            *v = a + u;
        }
        Some(breached)
    }

    /// Matched `ctc` gains: `pd`'s joint i obeys m_i ë + K2 ė + K1 K2 e ≈ 0,
    /// so K_p' = K1 K2 / m_i and K_d' = K2 / m_i give the same poles, with
    /// m_i = 1 / (M⁻¹)_ii (the joint's effective inertia) at `q`, from the
    /// law's own model. A joint whose m_i is not a finite positive number
    /// (a singular model) keeps the as-given K1 K2, K1 + K2; so does every
    /// joint without a model (`new` refuses that for `ctc`).
    fn matched_ctc_gains(&mut self, q: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let n = self.n;
        let m = match self.model.as_mut() {
            Some(d) => effective_inertia(d, q),
            None => vec![f64::NAN; n],
        };
        (0..n)
            .map(|i| {
                let (k1, k2) = (self.k1[i], self.k2[i]);
                match m[i] {
                    m if m.is_finite() && m > 0.0 => (k1 * k2 / m, k2 / m),
                    _ => (k1 * k2, k1 + k2),
                }
            })
            .unzip()
    }

    /// τ from the feedback and the model: G(q) for `pd-gravity`; for `ctc`
    /// M(q) v + C(q, q̇) q̇ + G(q), one Newton–Euler pass with q̈ = v. Its
    /// feedback acts through M, so all of it is the model term.
    fn model_terms(&mut self, input: &ControllerInput<'_>, out: &mut Diagnostics) {
        let n = self.n;
        match (self.kind, self.model.as_mut()) {
            (FeedbackKind::PdGravity, Some(m)) => {
                out.tau_model.copy_from_slice(m.gravity(input.q));
            }
            (FeedbackKind::Ctc | FeedbackKind::CbfCtc | FeedbackKind::Mpc, Some(m)) => {
                out.tau_model
                    .copy_from_slice(m.inverse(input.q, input.qd, &self.v));
                out.tau_feedback.iter_mut().for_each(|x| *x = 0.0);
            }
            // `new` refuses a model-based law without a model.
            (FeedbackKind::Pd | FeedbackKind::Smc, _)
            | (
                FeedbackKind::PdGravity
                | FeedbackKind::Ctc
                | FeedbackKind::CbfCtc
                | FeedbackKind::Mpc,
                None,
            ) => out.tau_model.iter_mut().for_each(|x| *x = 0.0),
        }
        for i in 0..n {
            out.tau[i] = out.tau_model[i] + out.tau_feedback[i];
        }
    }
}

/// One joint of the CBF–QP: the u nearest `u_nom` with 2 e u ≤ b and
/// |u| ≤ a, and whether the CBF row bound (u_nom broke it). The feasible
/// set is an interval; if it is empty (the row asks for more than the
/// bound allows) u is the bound's end that comes nearest to the row, the
/// most the motors can do. At e = 0 the row does not involve u.
pub(crate) fn cbf_interval(e: f64, b: f64, a: f64, u_nom: f64) -> (f64, bool) {
    // The row as a bound on u: above it for e > 0, below it for e < 0.
    let row = b / (2.0 * e);
    let (lo, hi, binds) = if e > 0.0 {
        (-a, row.min(a), u_nom > row)
    } else if e < 0.0 {
        (row.max(-a), a, u_nom < row)
    } else {
        (-a, a, false)
    };
    match lo <= hi {
        // max then min, not clamp: clamp panics on a NaN bound.
        true => (u_nom.max(lo).min(hi), binds),
        // Empty: the row's side of the box.
        false if e > 0.0 => (-a, true),
        false => (a, true),
    }
}

/// 1 / (M(q)⁻¹)_ii per joint; M's columns from inverse dynamics at rest
/// (M e_k = τ(q, 0, e_k) − G(q)). A singular M falls back to M_ii.
pub fn effective_inertia(d: &mut Dynamics, q: &[f64]) -> Vec<f64> {
    let n = q.len();
    let zero = vec![0.0; n];
    let g = d.gravity(q).to_vec();
    let mut m = nalgebra::DMatrix::zeros(n, n);
    for k in 0..n {
        let mut e = zero.clone();
        e[k] = 1.0;
        let col = d.inverse(q, &zero, &e);
        for i in 0..n {
            m[(i, k)] = col[i] - g[i];
        }
    }
    let diag: Vec<f64> = (0..n).map(|i| m[(i, i)]).collect();
    match m.try_inverse() {
        Some(inv) => (0..n).map(|i| 1.0 / inv[(i, i)]).collect(),
        None => diag,
    }
}

#[cfg(test)]
#[path = "feedback_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "robust_tests.rs"]
mod robust_tests;
