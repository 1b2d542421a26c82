//! How an action's torque reaches the plant between two decisions: held
//! (a step at every decision, 50 a second at the default decimation),
//! ramped across the decision, or low-pass filtered. The environment and
//! the Rust policy node (`policy/`) both drive one [`ActionShaper`], so a
//! policy's torque in a run is its torque in training, bit for bit.

use crate::options::Smoothing;

/// The torque an action adds in each plant period of its decision.
#[derive(Debug, Clone)]
pub struct ActionShaper {
    smoothing: Smoothing,
    decimation: u32,
    /// The low-pass's fraction per period, 1 − exp(−dt/τ).
    alpha: f64,
    /// The torque when the decision was taken.
    from: Vec<f64>,
    /// The decision's torque.
    to: Vec<f64>,
    /// The torque of the current period.
    now: Vec<f64>,
    /// Periods of the current decision already given.
    given: u32,
}

impl ActionShaper {
    /// A shaper for `n` joints, `decimation` periods of `dt` s a
    /// decision, all torques zero.
    pub fn new(smoothing: Smoothing, decimation: u32, dt: f64, n: usize) -> Self {
        let alpha = match smoothing {
            Smoothing::LowPass { tau_s } => -(-dt / tau_s).exp_m1(),
            Smoothing::Hold | Smoothing::Ramp => 1.0,
        };
        Self {
            smoothing,
            decimation: decimation.max(1),
            alpha,
            from: vec![0.0; n],
            to: vec![0.0; n],
            now: vec![0.0; n],
            given: 0,
        }
    }

    /// Back to no torque, as at an episode's start.
    pub fn reset(&mut self) {
        self.from.fill(0.0);
        self.to.fill(0.0);
        self.now.fill(0.0);
        self.given = 0;
    }

    /// A decision: `target` is its torque (what [`crate::action_torque`]
    /// wrote).
    pub fn decide(&mut self, target: &[f64]) {
        self.from.copy_from_slice(&self.now);
        self.to.copy_from_slice(target);
        self.given = 0;
    }

    /// The torque to add in the next plant period of the decision.
    pub fn period_torque(&mut self) -> &[f64] {
        self.given = self.given.saturating_add(1);
        match self.smoothing {
            // A copy, not arithmetic: the held torque keeps its bits.
            Smoothing::Hold => self.now.copy_from_slice(&self.to),
            Smoothing::Ramp if self.given >= self.decimation => {
                self.now.copy_from_slice(&self.to);
            }
            Smoothing::Ramp => {
                let f = f64::from(self.given) / f64::from(self.decimation);
                for ((now, from), to) in self.now.iter_mut().zip(&self.from).zip(&self.to) {
                    *now = from + (to - from) * f;
                }
            }
            Smoothing::LowPass { .. } => {
                for (now, to) in self.now.iter_mut().zip(&self.to) {
                    *now += (to - *now) * self.alpha;
                }
            }
        }
        &self.now
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::EnvError;

    fn periods(s: Smoothing, d: u32, decisions: &[f64]) -> Vec<f64> {
        let mut shaper = ActionShaper::new(s, d, 0.001, 1);
        let mut out = Vec::new();
        for &a in decisions {
            shaper.decide(&[a]);
            for _ in 0..d {
                out.push(shaper.period_torque()[0]);
            }
        }
        out
    }

    #[test]
    fn hold_repeats_the_decision() {
        assert_eq!(
            periods(Smoothing::Hold, 2, &[1.0, -3.0]),
            [1.0, 1.0, -3.0, -3.0]
        );
    }

    #[test]
    fn a_ramp_reaches_each_decision_at_its_last_period() {
        assert_eq!(
            periods(Smoothing::Ramp, 4, &[4.0, 0.0]),
            [1.0, 2.0, 3.0, 4.0, 3.0, 2.0, 1.0, 0.0]
        );
    }

    #[test]
    fn a_low_pass_approaches_the_decision_with_its_time_constant() {
        // 10 τ later: within e^−10 of the target.
        let out = periods(Smoothing::LowPass { tau_s: 0.001 }, 10, &[1.0]);
        assert!((out[9] - (1.0 - (-10.0f64).exp())).abs() < 1e-12, "{out:?}");
        assert!(out.windows(2).all(|w| w[1] > w[0]));
    }

    #[test]
    fn names_and_bad_values_are_refused_by_option() {
        assert_eq!(Smoothing::parse("ramp", f64::NAN).unwrap(), Smoothing::Ramp);
        for (name, tau, option) in [
            ("spline", 0.1, "smoothing"),
            ("low-pass", 0.0, "smoothing_tau_s"),
            ("low-pass", f64::NAN, "smoothing_tau_s"),
        ] {
            match Smoothing::parse(name, tau) {
                Err(EnvError::Option { name, .. }) => assert_eq!(name, option),
                other => panic!("{name} {tau}: {other:?}"),
            }
        }
    }
}
