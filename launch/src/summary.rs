//! The numbers that judge a run, computed step by step from [`StepRecord`]s.
//!
//! One code path for every way a run is made (in process, over IPC, from a
//! log), so that the same steps always give the same summary.

use serde::Serialize;

use plant_rapier::Effects;

use crate::record::StepRecord;

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
}

/// The plant effects of a run, as its logged states flag them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectsSummary {
    /// Every effect that acted at some step (names of `plant_rapier::Effects`).
    pub active: Vec<&'static str>,
    /// Steps whose torque was clipped at an effort limit.
    pub saturated_steps: u64,
    /// Commands lost on the way to the motors.
    pub dropped_commands: u64,
    /// Steps where no new command reached the motors (lost or late).
    pub held_commands: u64,
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
    breached: u64,
    faults: u64,
    finite: bool,
    effects_seen: u32,
    saturated: u64,
    dropped: u64,
    held: u64,
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
            breached: 0,
            faults: 0,
            finite: true,
            effects_seen: 0,
            saturated: 0,
            dropped: 0,
            held: 0,
        }
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
        self.dropped += u64::from(e.has(Effects::COMMAND_DROPPED));
        self.held += u64::from(e.has(Effects::COMMAND_HELD));
        self.breached += u64::from(r.barrier_breached);
        self.faults += u64::from(r.fault);
        let all_finite = [r.q, r.qd, r.tau, r.z1, r.z2, r.wa_norm]
            .iter()
            .all(|s| s.iter().all(|x| x.is_finite()));
        self.finite &= all_finite && !r.fault;
        let after = r.t >= self.tc;
        self.after_tc += u64::from(after);
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

    /// The summary of the steps added so far.
    pub fn finish(&self) -> Summary {
        let any_after = self.after_tc > 0;
        let when = |v: f64| any_after.then_some(v);
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
            })
            .collect();
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
                dropped_commands: self.dropped,
                held_commands: self.held,
            },
            constraint_satisfied_after_tc: satisfied,
            barrier_breached_steps: self.breached,
            fault_steps: self.faults,
            finite: self.finite,
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
            barrier_breached: false,
            fault: false,
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
