//! The numbers that judge a run, computed step by step from [`StepRecord`]s.
//!
//! One code path for every way a run is made (in process, over IPC, from a
//! log), so that the same steps always give the same summary.

use serde::Serialize;

use wire::Effects;

use crate::record::StepRecord;
use crate::smoothness::SmoothnessBuilder;

/// Per-joint results.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointSummary {
    /// Joint name from the URDF.
    pub name: String,
    /// max |Z1| over t ≥ T_c (None if the run ends before T_c).
    pub max_abs_error_after_tc: Option<f64>,
    /// min (k_c − |Z1|) over t ≥ T_c.
    pub min_margin_after_tc: Option<f64>,
    /// max over all t of |Z1γ| / k_c.
    pub max_gamma_error_ratio: f64,
    /// RMS of Z1 over t ≥ T_c.
    pub rms_error_after_tc: Option<f64>,
    /// ∫ τ² dt over the run (τ held over each period), N² m² s.
    pub effort_integral: f64,
    /// ∫ τ² dt over t ≥ T_c (the opening kick dominates the whole-run figure).
    pub effort_integral_after_tc: f64,
    /// max |τ|.
    pub max_abs_torque: f64,
    /// max ‖Ŵ_a‖ (column norm).
    pub max_actor_weight_norm: f64,
    /// IAE ∫|e| dt over t ≥ T_c, rad s.
    pub iae_after_tc: Option<f64>,
    /// ISE ∫e² dt over t ≥ T_c, rad² s.
    pub ise_after_tc: Option<f64>,
    /// ITAE ∫t|e| dt over t ≥ T_c (t from the start of the run), rad s².
    pub itae_after_tc: Option<f64>,
    /// When |e| < k_c held from then to the end (0: always inside; None:
    /// outside at the last step), s.
    pub entered_envelope_s: Option<f64>,
    /// ∫1[|e| ≥ k_c] dt over the run, s.
    pub violation_s: f64,
    /// ∫1[|e| ≥ k_c] dt over t ≥ T_c, s.
    pub violation_after_tc_s: f64,
    /// Torque rate ∫τ̇² dt with τ̇ the change between steps over Δt (the
    /// first step's rise from rest excluded), N² m² / s.
    pub torque_rate_integral: f64,
    /// CAPS's spectral smoothness of τ over the run, the amplitude-weighted
    /// mean frequency 2/(n f_s) Σ M_i f_i ([`crate::smoothness`]), N m;
    /// lower is smoother (None: no step).
    pub torque_smoothness: Option<f64>,
}

/// The whole run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Number of actuated joints.
    pub dof: usize,
    /// Control steps taken.
    pub steps: u64,
    /// Control period, s.
    pub dt_s: f64,
    /// Prescribed time T_c, s.
    pub tc_s: f64,
    /// Per joint, in joint order.
    pub joints: Vec<JointSummary>,
    /// What the plant added that the controller does not know.
    pub effects: EffectsSummary,
    /// |Z1_i| < k_c,i for every joint at every step with t ≥ T_c (false if
    /// the run has no such step).
    pub constraint_satisfied_after_tc: bool,
    /// Steps where the controller's guard clamped D.
    pub barrier_breached_steps: u64,
    /// Steps where the controller published zero torque because of a fault.
    pub fault_steps: u64,
    /// Every state, torque and error was finite and no step faulted.
    pub finite: bool,
    /// Sim time of the first step that was not (None: every step was).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_non_finite_s: Option<f64>,
    /// The metrics of BASELINES.md for the whole arm.
    pub metrics: ArmMetrics,
}

/// BASELINES.md's metrics for the whole arm: sums over joints of the
/// integrals, the worst joint for the rest.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArmMetrics {
    /// Σ IAE over t ≥ T_c.
    pub iae_after_tc: Option<f64>,
    /// Σ ISE over t ≥ T_c.
    pub ise_after_tc: Option<f64>,
    /// Σ ITAE over t ≥ T_c.
    pub itae_after_tc: Option<f64>,
    /// RMS of e over every joint and step with t ≥ T_c.
    pub rms_error_after_tc: Option<f64>,
    /// max |e| over t ≥ T_c.
    pub max_abs_error_after_tc: Option<f64>,
    /// min (k_c − |e|) over t ≥ T_c.
    pub min_margin_after_tc: Option<f64>,
    /// When every joint was inside for good (None: some joint ends outside).
    pub entered_envelope_s: Option<f64>,
    /// Time with some joint at or outside its envelope, s.
    pub violation_s: f64,
    /// The same over t ≥ T_c, s.
    pub violation_after_tc_s: f64,
    /// Σ ∫τ² dt over the run.
    pub effort: f64,
    /// Σ ∫τ² dt over t ≥ T_c.
    pub effort_after_tc: f64,
    /// Σ ∫(τ − G(q))² dt over t ≥ T_c, with G the URDF's static gravity
    /// load at the true q: the effort beyond holding the arm still (∫τ²
    /// after T_c is mostly that hold). None where the summary was made
    /// without the arm's model.
    pub effort_beyond_gravity_after_tc: Option<f64>,
    /// Σ ∫|τ q̇| dt over t ≥ T_c: the mechanical energy through the
    /// motors, J (unlike ∫τ², holding a static load costs none).
    pub energy_after_tc: f64,
    /// Σ ∫τ̇² dt.
    pub torque_rate: f64,
    /// Σ over joints of the torque's spectral smoothness (CAPS's Sm), N m.
    pub torque_smoothness: Option<f64>,
    /// max |τ| over joints and steps.
    pub peak_abs_torque: f64,
    /// Time with some torque clipped at its effort limit, s.
    pub saturated_s: f64,
    /// Steps where the law's guard acted (barrier clamp, or funnel clamp for `ppc`).
    pub breaches: u64,
    /// max |actor torque| over joints and steps: what the networks add.
    pub peak_actor_torque: f64,
    /// Σ ∫τ_actor² dt over the run.
    pub actor_effort: f64,
}

/// The plant effects of a run, as its logged states flag them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectsSummary {
    /// Every effect that acted at some step (names of `wire::Effects`).
    pub active: Vec<&'static str>,
    /// Steps whose torque was clipped at an effort limit.
    pub saturated_steps: u64,
    /// Commands lost on the way to the motors.
    pub dropped_commands: u64,
    /// Steps where no new command reached the motors (lost or late).
    pub held_commands: u64,
    /// Periods in which a link touched an obstacle (`[plant.contact]`).
    pub contact_steps: u64,
}

/// Accumulates a [`Summary`] one step at a time.
#[derive(Debug, Clone)]
pub struct SummaryBuilder {
    tc: f64,
    dt: f64,
    names: Vec<String>,
    steps: u64,
    after_tc: u64,
    max_err: Vec<f64>,
    min_margin: Vec<f64>,
    max_ratio: Vec<f64>,
    sum_sq_err: Vec<f64>,
    effort: Vec<f64>,
    effort_after: Vec<f64>,
    max_tau: Vec<f64>,
    max_wa: Vec<f64>,
    iae: Vec<f64>,
    itae: Vec<f64>,
    last_violation: Vec<Option<f64>>,
    violation: Vec<f64>,
    violation_after: Vec<f64>,
    any_violation: f64,
    any_violation_after: f64,
    prev_tau: Option<Vec<f64>>,
    torque_rate: Vec<f64>,
    smoothness: SmoothnessBuilder,
    peak_actor: f64,
    actor_effort: f64,
    energy_after: f64,
    t_last: f64,
    breached: u64,
    faults: u64,
    finite: bool,
    first_non_finite: Option<f64>,
    effects_seen: u32,
    saturated: u64,
    contact: u64,
    dropped: u64,
    held: u64,
    /// The URDF's Newton–Euler model, for G(q) (see [`SummaryBuilder::with_gravity`]).
    gravity: Option<Box<arm_model::dynamics::Dynamics>>,
    effort_beyond_gravity: f64,
}

impl SummaryBuilder {
    /// For joints `names`, period `dt` s and prescribed time `tc` s.
    pub fn new(names: Vec<String>, dt: f64, tc: f64) -> Self {
        let n = names.len();
        Self {
            tc,
            dt,
            names,
            steps: 0,
            after_tc: 0,
            max_err: vec![0.0; n],
            min_margin: vec![f64::INFINITY; n],
            max_ratio: vec![0.0; n],
            sum_sq_err: vec![0.0; n],
            effort: vec![0.0; n],
            effort_after: vec![0.0; n],
            max_tau: vec![0.0; n],
            max_wa: vec![0.0; n],
            iae: vec![0.0; n],
            itae: vec![0.0; n],
            last_violation: vec![None; n],
            violation: vec![0.0; n],
            violation_after: vec![0.0; n],
            any_violation: 0.0,
            any_violation_after: 0.0,
            prev_tau: None,
            torque_rate: vec![0.0; n],
            smoothness: SmoothnessBuilder::new(n, dt),
            peak_actor: 0.0,
            actor_effort: 0.0,
            energy_after: 0.0,
            t_last: 0.0,
            breached: 0,
            faults: 0,
            finite: true,
            first_non_finite: None,
            effects_seen: 0,
            saturated: 0,
            contact: 0,
            dropped: 0,
            held: 0,
            gravity: None,
            effort_beyond_gravity: 0.0,
        }
    }

    /// Also integrates the effort beyond the static gravity load of
    /// `model` (the URDF's, as the controller's designer knows it: no
    /// payload, standard gravity) after T_c.
    pub fn with_gravity(mut self, model: &arm_model::ArmModel) -> Self {
        self.gravity = Some(Box::new(arm_model::dynamics::Dynamics::new(model, 1.0)));
        self
    }

    /// Adds one step. NaN anywhere makes `finite` false and, through
    /// `max`/`min` that propagate NaN, shows in the affected figures.
    /// Errors are judged on the true state: with sensor noise the
    /// controller's Z1 is not the arm's error.
    pub fn add(&mut self, r: &StepRecord<'_>) {
        self.steps += 1;
        let e = Effects(r.effects);
        self.effects_seen |= r.effects;
        self.saturated += u64::from(e.has(Effects::SATURATED));
        self.contact += u64::from(e.has(Effects::CONTACT));
        self.dropped += u64::from(e.has(Effects::COMMAND_DROPPED));
        self.held += u64::from(e.has(Effects::COMMAND_HELD));
        self.breached += u64::from(r.barrier_breached);
        self.faults += u64::from(r.fault);
        let all_finite = [r.q, r.qd, r.tau, r.z1, r.z2, r.wa_norm]
            .iter()
            .all(|s| s.iter().all(|x| x.is_finite()));
        if (r.fault || !all_finite) && self.first_non_finite.is_none() {
            self.first_non_finite = Some(r.t);
        }
        self.finite &= all_finite && !r.fault;
        let after = r.t >= self.tc;
        self.after_tc += u64::from(after);
        self.add_baseline_metrics(r, after);
        self.smoothness.add(&r.tau[..self.names.len()]);
        if let (true, Some(d)) = (after, self.gravity.as_mut()) {
            let g = d.gravity(r.q);
            self.effort_beyond_gravity += r
                .tau
                .iter()
                .zip(g)
                .map(|(t, g)| (t - g) * (t - g) * self.dt)
                .sum::<f64>();
        }
        for i in 0..self.names.len() {
            let e = (r.q[i] - r.q_d[i]).abs();
            self.max_ratio[i] = nan_max(self.max_ratio[i], r.z1g[i].abs() / r.kc[i]);
            let tau2 = r.tau[i] * r.tau[i] * self.dt;
            self.effort[i] += tau2;
            self.max_tau[i] = nan_max(self.max_tau[i], r.tau[i].abs());
            self.max_wa[i] = nan_max(self.max_wa[i], r.wa_norm[i]);
            if after {
                self.max_err[i] = nan_max(self.max_err[i], e);
                self.min_margin[i] = nan_min(self.min_margin[i], r.kc[i] - e);
                self.sum_sq_err[i] += e * e;
                self.effort_after[i] += tau2;
            }
        }
    }

    /// The integrals and times of BASELINES.md's metrics for one step.
    fn add_baseline_metrics(&mut self, r: &StepRecord<'_>, after: bool) {
        let dt = self.dt;
        self.t_last = r.t;
        let mut any = false;
        for i in 0..self.names.len() {
            let e = (r.q[i] - r.q_d[i]).abs();
            // NaN counts as outside.
            let outside = e.partial_cmp(&r.kc[i]) != Some(std::cmp::Ordering::Less);
            if outside {
                any = true;
                self.last_violation[i] = Some(r.t);
                self.violation[i] += dt;
                if after {
                    self.violation_after[i] += dt;
                }
            }
            if after {
                self.iae[i] += e * dt;
                self.itae[i] += r.t * e * dt;
                self.energy_after += (r.tau[i] * r.qd[i]).abs() * dt;
            }
            self.peak_actor = nan_max(self.peak_actor, r.tau_actor[i].abs());
            self.actor_effort += r.tau_actor[i] * r.tau_actor[i] * dt;
            if let Some(prev) = &self.prev_tau {
                let d = r.tau[i] - prev[i];
                self.torque_rate[i] += d * d / dt;
            }
        }
        if any {
            self.any_violation += dt;
            if after {
                self.any_violation_after += dt;
            }
        }
        match self.prev_tau.as_mut() {
            Some(p) => p.copy_from_slice(r.tau),
            None => self.prev_tau = Some(r.tau.to_vec()),
        }
    }

    /// When joint `i` entered its envelope for good.
    fn entered(&self, i: usize) -> Option<f64> {
        match self.last_violation[i] {
            None => Some(0.0),
            Some(t) if t >= self.t_last => None,
            Some(t) => Some(t + self.dt),
        }
    }

    /// The summary of the steps added so far.
    pub fn finish(&self) -> Summary {
        let any_after = self.after_tc > 0;
        let when = |v: f64| any_after.then_some(v);
        let smoothness = self.smoothness.finish();
        let joints: Vec<JointSummary> = (0..self.names.len())
            .map(|i| JointSummary {
                name: self.names[i].clone(),
                max_abs_error_after_tc: when(self.max_err[i]),
                min_margin_after_tc: when(self.min_margin[i]),
                max_gamma_error_ratio: self.max_ratio[i],
                rms_error_after_tc: when((self.sum_sq_err[i] / self.after_tc.max(1) as f64).sqrt()),
                effort_integral: self.effort[i],
                effort_integral_after_tc: self.effort_after[i],
                max_abs_torque: self.max_tau[i],
                max_actor_weight_norm: self.max_wa[i],
                iae_after_tc: when(self.iae[i]),
                ise_after_tc: when(self.sum_sq_err[i] * self.dt),
                itae_after_tc: when(self.itae[i]),
                entered_envelope_s: self.entered(i),
                violation_s: self.violation[i],
                violation_after_tc_s: self.violation_after[i],
                torque_rate_integral: self.torque_rate[i],
                torque_smoothness: smoothness[i],
            })
            .collect();
        let metrics = self.arm_metrics(&joints, any_after);
        let satisfied = any_after
            && joints
                .iter()
                .all(|j| j.min_margin_after_tc.is_some_and(|m| m > 0.0));
        Summary {
            dof: self.names.len(),
            steps: self.steps,
            dt_s: self.dt,
            tc_s: self.tc,
            joints,
            effects: EffectsSummary {
                active: Effects(self.effects_seen).names(),
                saturated_steps: self.saturated,
                contact_steps: self.contact,
                dropped_commands: self.dropped,
                held_commands: self.held,
            },
            constraint_satisfied_after_tc: satisfied,
            barrier_breached_steps: self.breached,
            fault_steps: self.faults,
            finite: self.finite,
            first_non_finite_s: self.first_non_finite,
            metrics,
        }
    }

    fn arm_metrics(&self, joints: &[JointSummary], any_after: bool) -> ArmMetrics {
        let when = |v: f64| any_after.then_some(v);
        let sum = |f: fn(&JointSummary) -> f64| joints.iter().map(f).sum::<f64>();
        let fold = |f: fn(&JointSummary) -> Option<f64>, max: bool| {
            let mut vals = joints.iter().map(f);
            if max {
                vals.try_fold(0.0, |a, b| Some(nan_max(a, b?)))
            } else {
                vals.try_fold(f64::INFINITY, |a, b| Some(nan_min(a, b?)))
            }
        };
        let n_after = (self.after_tc as usize * joints.len()).max(1) as f64;
        ArmMetrics {
            iae_after_tc: when(self.iae.iter().sum()),
            ise_after_tc: when(self.sum_sq_err.iter().sum::<f64>() * self.dt),
            itae_after_tc: when(self.itae.iter().sum()),
            rms_error_after_tc: when((self.sum_sq_err.iter().sum::<f64>() / n_after).sqrt()),
            max_abs_error_after_tc: fold(|j| j.max_abs_error_after_tc, true),
            min_margin_after_tc: fold(|j| j.min_margin_after_tc, false),
            entered_envelope_s: fold(|j| j.entered_envelope_s, true),
            violation_s: self.any_violation,
            violation_after_tc_s: self.any_violation_after,
            effort: sum(|j| j.effort_integral),
            effort_after_tc: sum(|j| j.effort_integral_after_tc),
            effort_beyond_gravity_after_tc: self
                .gravity
                .as_ref()
                .map(|_| self.effort_beyond_gravity),
            energy_after_tc: self.energy_after,
            torque_rate: sum(|j| j.torque_rate_integral),
            torque_smoothness: joints
                .iter()
                .map(|j| j.torque_smoothness)
                .sum::<Option<f64>>(),
            peak_abs_torque: joints.iter().map(|j| j.max_abs_torque).fold(0.0, nan_max),
            saturated_s: self.saturated as f64 * self.dt,
            breaches: self.breached,
            peak_actor_torque: self.peak_actor,
            actor_effort: self.actor_effort,
        }
    }
}

fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

fn nan_min(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.min(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec<'a>(
        t: f64,
        z1: &'a [f64],
        z1g: &'a [f64],
        tau: &'a [f64],
        kc: &'a [f64],
    ) -> StepRecord<'a> {
        StepRecord {
            t,
            q: z1,
            qd: z1,
            q_measured: z1,
            qd_measured: z1,
            qdd: z1,
            tau,
            disturbance: tau,
            effects: 0,
            q_d: &[0.0],
            qd_d: z1,
            kc,
            z1,
            z1g,
            z2: z1,
            wa_norm: tau,
            tau_actor: tau,
            barrier_breached: false,
            fault: false,
            own: &[],
        }
    }

    #[test]
    fn metrics_by_hand() {
        let mut b = SummaryBuilder::new(vec!["a".into()], 0.5, 1.0);
        b.add(&rec(0.0, &[0.8], &[0.0], &[2.0], &[0.5]));
        b.add(&rec(0.5, &[0.4], &[0.35], &[-1.0], &[0.5]));
        b.add(&rec(1.0, &[0.3], &[0.3], &[1.0], &[0.5]));
        b.add(&rec(1.5, &[-0.4], &[-0.4], &[0.5], &[0.5]));
        let s = b.finish();
        let j = &s.joints[0];
        assert_eq!(j.max_abs_error_after_tc, Some(0.4));
        assert!((j.min_margin_after_tc.unwrap() - 0.1).abs() < 1e-15);
        assert_eq!(j.max_gamma_error_ratio, 0.8);
        assert!((j.rms_error_after_tc.unwrap() - ((0.09 + 0.16) / 2.0f64).sqrt()).abs() < 1e-15);
        assert_eq!(j.effort_integral, (4.0 + 1.0 + 1.0 + 0.25) * 0.5);
        assert_eq!(j.effort_integral_after_tc, (1.0 + 0.25) * 0.5);
        assert_eq!(j.max_abs_torque, 2.0);
        assert!(s.constraint_satisfied_after_tc && s.finite);
        // BASELINES.md's metrics, after T_c = 1 s, Δt = 0.5 s.
        let close = |a: Option<f64>, b: f64| assert!((a.unwrap() - b).abs() < 1e-15, "{a:?} {b}");
        close(j.iae_after_tc, (0.3 + 0.4) * 0.5);
        close(j.ise_after_tc, (0.09 + 0.16) * 0.5);
        close(j.itae_after_tc, (1.0 * 0.3 + 1.5 * 0.4) * 0.5);
        assert_eq!((j.violation_s, j.violation_after_tc_s), (0.5, 0.0));
        assert_eq!(j.entered_envelope_s, Some(0.5));
        assert_eq!(j.torque_rate_integral, (9.0 + 4.0 + 0.25) / 0.5);
        let m = &s.metrics;
        assert_eq!(
            (m.iae_after_tc, m.effort_after_tc),
            (j.iae_after_tc, 1.25 * 0.5)
        );
        assert_eq!((m.violation_s, m.entered_envelope_s), (0.5, Some(0.5)));
        assert_eq!(m.peak_abs_torque, 2.0);
    }

    #[test]
    fn ending_outside_never_enters_for_good() {
        let mut b = SummaryBuilder::new(vec!["a".into()], 0.5, 1.0);
        b.add(&rec(0.0, &[0.1], &[0.0], &[1.0], &[0.5]));
        b.add(&rec(0.5, &[0.6], &[0.6], &[1.0], &[0.5]));
        let s = b.finish();
        assert_eq!(s.joints[0].entered_envelope_s, None);
        assert_eq!(s.metrics.entered_envelope_s, None);
        assert_eq!(s.metrics.violation_s, 0.5);
    }

    #[test]
    fn a_violation_after_tc_and_a_nan_are_reported() {
        let mut b = SummaryBuilder::new(vec!["a".into()], 0.5, 1.0);
        b.add(&rec(1.0, &[0.6], &[0.6], &[1.0], &[0.5]));
        let s = b.finish();
        assert!(!s.constraint_satisfied_after_tc);
        b.add(&rec(1.5, &[f64::NAN], &[0.1], &[1.0], &[0.5]));
        assert!(!b.finish().finite);
    }

    #[test]
    fn a_run_shorter_than_tc_has_no_after_tc_figures() {
        let mut b = SummaryBuilder::new(vec!["a".into()], 0.5, 1.0);
        b.add(&rec(0.0, &[0.1], &[0.0], &[1.0], &[0.5]));
        let s = b.finish();
        assert_eq!(s.joints[0].max_abs_error_after_tc, None);
        assert!(!s.constraint_satisfied_after_tc);
    }
}
