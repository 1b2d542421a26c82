//! One smooth periodic signal and its first two derivatives.

use serde::{Deserialize, Serialize};

use crate::TrajectoryError;

/// `offset + sin·sin(ωt) + cos·cos(ωt)`: any sinusoid, written so that the
/// paper's `sin(2t)` and `cos(t)` are exact (no phase shift by π/2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sinusoid {
    /// Constant term (default: 0).
    pub offset: f64,
    /// Amplitude of sin(ωt) (default: 0).
    pub sin: f64,
    /// Amplitude of cos(ωt) (default: 0).
    pub cos: f64,
    /// Angular frequency ω, rad/s (default: 0).
    pub omega: f64,
}

impl Default for Sinusoid {
    fn default() -> Self {
        Self {
            offset: 0.0,
            sin: 0.0,
            cos: 0.0,
            omega: 0.0,
        }
    }
}

impl Sinusoid {
    /// Value, first and second derivative at `t`.
    pub fn eval(&self, t: f64) -> [f64; 3] {
        let (s, c) = (self.omega * t).sin_cos();
        let w = self.omega;
        [
            self.offset + self.sin * s + self.cos * c,
            w * (self.sin * c - self.cos * s),
            -w * w * (self.sin * s + self.cos * c),
        ]
    }

    /// Peak deviation from the offset.
    pub fn amplitude(&self) -> f64 {
        self.sin.hypot(self.cos)
    }

    /// The smallest value the signal reaches (over all t when ω ≠ 0).
    pub fn min_value(&self) -> f64 {
        if self.omega == 0.0 {
            self.offset + self.cos
        } else {
            self.offset - self.amplitude()
        }
    }

    /// The largest value the signal reaches.
    pub fn max_value(&self) -> f64 {
        if self.omega == 0.0 {
            self.offset + self.cos
        } else {
            self.offset + self.amplitude()
        }
    }

    pub(crate) fn validate(&self, field: &str) -> Result<(), TrajectoryError> {
        for (name, value) in [
            ("offset", self.offset),
            ("sin", self.sin),
            ("cos", self.cos),
            ("omega", self.omega),
        ] {
            if !value.is_finite() {
                return Err(TrajectoryError::NotFinite {
                    field: format!("{field}.{name}"),
                    value,
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The analytic derivatives agree with central differences.
        #[test]
        fn derivatives_match_finite_differences(
            offset in -2.0..2.0f64, sin in -2.0..2.0f64, cos in -2.0..2.0f64,
            omega in -5.0..5.0f64, t in 0.0..30.0f64,
        ) {
            let s = Sinusoid { offset, sin, cos, omega };
            let h = 1e-5;
            let [_, d1, d2] = s.eval(t);
            let fd1 = (s.eval(t + h)[0] - s.eval(t - h)[0]) / (2.0 * h);
            let fd2 = (s.eval(t + h)[1] - s.eval(t - h)[1]) / (2.0 * h);
            // Central differences are O(h²) accurate: |f'''| h² ≤ 250·1e-10.
            prop_assert!((d1 - fd1).abs() < 1e-7);
            prop_assert!((d2 - fd2).abs() < 1e-6);
        }
    }
}
