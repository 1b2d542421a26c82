//! One joint's signal as a researcher writes it: a sinusoid (the paper's
//! form), plus more sinusoids, smoothed steps and smoothed ramps, summed.
//! Every part is C² in time, so q̇_d and q̈_d exist everywhere and are exact.

use serde::{Deserialize, Serialize};

use crate::{Sinusoid, TrajectoryError};

/// `offset + sin·sin(ωt) + cos·cos(ωt)` plus every term of `sines`,
/// `steps` and `ramps`. A table with only the first four keys is the
/// paper's sinusoid, as before.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Signal {
    /// Constant term.
    pub offset: f64,
    /// Amplitude of sin(ωt).
    pub sin: f64,
    /// Amplitude of cos(ωt).
    pub cos: f64,
    /// Angular frequency ω, rad/s.
    pub omega: f64,
    /// More sinusoids, added (a sum of sines).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sines: Vec<Sine>,
    /// Steps, each smoothed by a minimum-jerk rise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub steps: Vec<Step>,
    /// Ramps: a constant rate between two times, its corners smoothed.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ramps: Vec<Ramp>,
}

/// `sin·sin(ωt) + cos·cos(ωt)`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sine {
    /// Amplitude of sin(ωt).
    pub sin: f64,
    /// Amplitude of cos(ωt).
    pub cos: f64,
    /// Angular frequency ω, rad/s.
    pub omega: f64,
}

/// A change of `by` that starts at `at` and is complete `rise_s` later,
/// along a minimum-jerk (quintic) curve: zero rate and acceleration at both
/// ends, so the law's q̈_d stays bounded.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// When the rise starts, s.
    pub at: f64,
    /// The change, rad or m.
    pub by: f64,
    /// How long the rise takes, s (> 0).
    pub rise_s: f64,
}

/// A rate `rate` from `at` to `until`, reached and left along minimum-jerk
/// velocity blends of `blend_s` centred on each corner; the total change is
/// `rate · (until − at)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ramp {
    /// When the ramp starts, s.
    pub at: f64,
    /// When it ends, s (> `at`).
    pub until: f64,
    /// Rate, rad/s or m/s.
    pub rate: f64,
    /// Width of each corner's blend, s (> 0, at most `until − at`).
    pub blend_s: f64,
}

/// The minimum-jerk blend s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ on [0, 1] and its two
/// derivatives, clamped to 0 before and 1 after.
fn smoothstep(tau: f64) -> [f64; 3] {
    if tau <= 0.0 {
        return [0.0; 3];
    }
    if tau >= 1.0 {
        return [1.0, 0.0, 0.0];
    }
    let (t2, t3) = (tau * tau, tau * tau * tau);
    [
        t3 * (10.0 - 15.0 * tau + 6.0 * t2),
        30.0 * t2 * (1.0 - 2.0 * tau + t2),
        60.0 * tau * (1.0 - 3.0 * tau + 2.0 * t2),
    ]
}

/// ∫₀^τ s: 2.5τ⁴ − 3τ⁵ + τ⁶ on [0, 1], then τ − ½.
fn smoothstep_integral(tau: f64) -> f64 {
    if tau <= 0.0 {
        0.0
    } else if tau >= 1.0 {
        tau - 0.5
    } else {
        tau.powi(4) * (2.5 - 3.0 * tau + tau * tau)
    }
}

impl Step {
    fn eval(&self, t: f64) -> [f64; 3] {
        let [s, d1, d2] = smoothstep((t - self.at) / self.rise_s);
        [
            self.by * s,
            self.by * d1 / self.rise_s,
            self.by * d2 / (self.rise_s * self.rise_s),
        ]
    }
}

impl Ramp {
    /// The velocity rises over [at − b/2, at + b/2] and falls over
    /// [until − b/2, until + b/2]: position is the rate times the
    /// difference of the two blends' integrals.
    fn eval(&self, t: f64) -> [f64; 3] {
        let b = self.blend_s;
        let (u1, u2) = ((t - self.at) / b + 0.5, (t - self.until) / b + 0.5);
        let [s1, d1, _] = smoothstep(u1);
        let [s2, d2, _] = smoothstep(u2);
        [
            self.rate * b * (smoothstep_integral(u1) - smoothstep_integral(u2)),
            self.rate * (s1 - s2),
            self.rate * (d1 - d2) / b,
        ]
    }

    fn total(&self) -> f64 {
        self.rate * (self.until - self.at)
    }
}

impl From<Sinusoid> for Signal {
    fn from(s: Sinusoid) -> Self {
        Self {
            offset: s.offset,
            sin: s.sin,
            cos: s.cos,
            omega: s.omega,
            ..Self::default()
        }
    }
}

impl Signal {
    fn base(&self) -> Sinusoid {
        Sinusoid {
            offset: self.offset,
            sin: self.sin,
            cos: self.cos,
            omega: self.omega,
        }
    }

    fn sine(s: &Sine) -> Sinusoid {
        Sinusoid {
            offset: 0.0,
            sin: s.sin,
            cos: s.cos,
            omega: s.omega,
        }
    }

    /// Value, first and second derivative at `t`.
    pub fn eval(&self, t: f64) -> [f64; 3] {
        let mut out = self.base().eval(t);
        let terms = (self.sines.iter().map(|s| Self::sine(s).eval(t)))
            .chain(self.steps.iter().map(|s| s.eval(t)))
            .chain(self.ramps.iter().map(|r| r.eval(t)));
        for v in terms {
            for k in 0..3 {
                out[k] += v[k];
            }
        }
        out
    }

    /// Peak deviation of the periodic part from the offset (sinusoids only).
    pub fn amplitude(&self) -> f64 {
        self.base().amplitude() + self.sines.iter().map(|s| s.sin.hypot(s.cos)).sum::<f64>()
    }

    /// A bound on |q̇| over all time.
    pub fn speed_bound(&self) -> f64 {
        let sines: f64 = (std::iter::once(self.base()))
            .chain(self.sines.iter().map(Self::sine))
            .map(|s| s.amplitude() * s.omega.abs())
            .sum();
        let steps: f64 = self
            .steps
            .iter()
            .map(|s| 1.875 * s.by.abs() / s.rise_s)
            .sum();
        let ramps: f64 = self.ramps.iter().map(|r| r.rate.abs()).sum();
        sines + steps + ramps
    }

    /// A bound on |q̈| over all time.
    pub fn accel_bound(&self) -> f64 {
        let sines: f64 = (std::iter::once(self.base()))
            .chain(self.sines.iter().map(Self::sine))
            .map(|s| s.amplitude() * s.omega * s.omega)
            .sum();
        // max |s''| = 10/√3 ≈ 5.774.
        let steps: f64 = self
            .steps
            .iter()
            .map(|s| 5.774 * s.by.abs() / (s.rise_s * s.rise_s))
            .sum();
        let ramps: f64 = self
            .ramps
            .iter()
            .map(|r| 1.875 * r.rate.abs() / r.blend_s)
            .sum();
        sines + steps + ramps
    }

    /// A lower bound on the value over all time.
    pub fn min_value(&self) -> f64 {
        let (lo, _) = self.range();
        lo
    }

    /// An upper bound on the value over all time.
    pub fn max_value(&self) -> f64 {
        let (_, hi) = self.range();
        hi
    }

    fn range(&self) -> (f64, f64) {
        let base = self.base();
        let (mut lo, mut hi) = (base.min_value(), base.max_value());
        for s in &self.sines {
            let a = if s.omega == 0.0 {
                s.cos
            } else {
                s.sin.hypot(s.cos)
            };
            let (l, h) = if s.omega == 0.0 { (a, a) } else { (-a, a) };
            lo += l;
            hi += h;
        }
        let changes = self
            .steps
            .iter()
            .map(|s| s.by)
            .chain(self.ramps.iter().map(Ramp::total));
        for c in changes {
            lo += c.min(0.0);
            hi += c.max(0.0);
        }
        (lo, hi)
    }

    pub(crate) fn validate(&self, field: &str) -> Result<(), TrajectoryError> {
        self.base().validate(field)?;
        let finite = |name: String, value: f64| {
            if value.is_finite() {
                Ok(())
            } else {
                Err(TrajectoryError::NotFinite { field: name, value })
            }
        };
        for (k, s) in self.sines.iter().enumerate() {
            for (n, v) in [("sin", s.sin), ("cos", s.cos), ("omega", s.omega)] {
                finite(format!("{field}.sines[{k}].{n}"), v)?;
            }
        }
        for (k, s) in self.steps.iter().enumerate() {
            let f = format!("{field}.steps[{k}]");
            for (n, v) in [("at", s.at), ("by", s.by), ("rise_s", s.rise_s)] {
                finite(format!("{f}.{n}"), v)?;
            }
            positive(
                &format!("{f}.rise_s"),
                s.rise_s,
                "a step rises over a positive time",
            )?;
        }
        for (k, r) in self.ramps.iter().enumerate() {
            let f = format!("{field}.ramps[{k}]");
            for (n, v) in [
                ("at", r.at),
                ("until", r.until),
                ("rate", r.rate),
                ("blend_s", r.blend_s),
            ] {
                finite(format!("{f}.{n}"), v)?;
            }
            positive(
                &format!("{f}.blend_s"),
                r.blend_s,
                "the corners blend over a positive time",
            )?;
            if r.until - r.at < r.blend_s {
                return Err(TrajectoryError::Invalid {
                    field: format!("{f}.until"),
                    reason: format!(
                        "the ramp must last at least its blend: until − at = {} < blend_s = {}",
                        r.until - r.at,
                        r.blend_s
                    ),
                });
            }
        }
        Ok(())
    }
}

fn positive(field: &str, v: f64, why: &str) -> Result<(), TrajectoryError> {
    if v > 0.0 {
        Ok(())
    } else {
        Err(TrajectoryError::Invalid {
            field: field.to_string(),
            reason: format!("{v} is not positive ({why})"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn check_derivatives(s: &Signal, t: f64) -> Result<(), TestCaseError> {
        let h = 1e-5;
        let [_, d1, d2] = s.eval(t);
        let fd1 = (s.eval(t + h)[0] - s.eval(t - h)[0]) / (2.0 * h);
        let fd2 = (s.eval(t + h)[1] - s.eval(t - h)[1]) / (2.0 * h);
        prop_assert!((d1 - fd1).abs() < 1e-6, "q̇ {d1} vs {fd1} at {t}");
        prop_assert!((d2 - fd2).abs() < 1e-4, "q̈ {d2} vs {fd2} at {t}");
        let (lo, hi) = s.range();
        let v = s.eval(t)[0];
        prop_assert!(
            lo - 1e-12 <= v && v <= hi + 1e-12,
            "{v} outside [{lo}, {hi}]"
        );
        prop_assert!(d1.abs() <= s.speed_bound() + 1e-9);
        prop_assert!(d2.abs() <= s.accel_bound() + 1e-9);
        Ok(())
    }

    proptest! {
        /// Every part's derivatives agree with central differences, and the
        /// bounds hold.
        #[test]
        fn derivatives_and_bounds_hold(
            a in -2.0..2.0f64, w in 0.1..5.0f64, at in 0.0..5.0f64, by in -2.0..2.0f64,
            rise in 0.2..3.0f64, rate in -1.0..1.0f64, len in 0.5..4.0f64, t in 0.0..12.0f64,
        ) {
            let s = Signal {
                offset: 0.3,
                sin: a,
                omega: w,
                sines: vec![Sine { sin: 0.1, cos: 0.2, omega: 3.0 }],
                steps: vec![Step { at, by, rise_s: rise }],
                ramps: vec![Ramp { at: at + 1.0, until: at + 1.0 + len, rate, blend_s: 0.5 }],
                ..Signal::default()
            };
            check_derivatives(&s, t)?;
        }
    }

    #[test]
    fn a_step_and_a_ramp_arrive_where_they_say() {
        let s = Signal {
            steps: vec![Step {
                at: 1.0,
                by: 0.5,
                rise_s: 0.4,
            }],
            ramps: vec![Ramp {
                at: 2.0,
                until: 4.0,
                rate: 0.25,
                blend_s: 0.2,
            }],
            ..Signal::default()
        };
        assert_eq!(s.eval(0.9), [0.0, 0.0, 0.0]);
        assert!((s.eval(1.4)[0] - 0.5).abs() < 1e-15);
        // Half-way along the ramp it has gone half its change, at its rate.
        let mid = s.eval(3.0);
        assert!((mid[0] - 0.75).abs() < 1e-12 && (mid[1] - 0.25).abs() < 1e-12);
        let end = s.eval(5.0);
        assert!((end[0] - 1.0).abs() < 1e-12 && end[1] == 0.0);
    }
}
