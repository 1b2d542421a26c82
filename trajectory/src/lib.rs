//! The reference trajectory q_d(t) and the constraint envelope k_c(t).
//!
//! Where it sits: the `trajectory` process (and the in-process loop of
//! `testbed sim`) calls [`Reference::sample_into`] each control period and
//! hands the controller q_d, q̇_d, q̈_d, k_c and k̇_c. Everything here is a pure
//! function of sim time: no clock, no I/O, so a log alone can reproduce it.
//!
//! Each signal is a [`Sinusoid`], `offset + sin·sin(ωt) + cos·cos(ωt)`, which
//! writes the paper's reference (Section IV) exactly:
//!
//! ```
//! use trajectory::{Reference, ReferenceConfig, EnvelopeConfig, ReferenceSample};
//! let reference = Reference::new(&ReferenceConfig::paper(), &EnvelopeConfig::paper()).unwrap();
//! let mut s = ReferenceSample::new(reference.dof());
//! reference.sample_into(0.0, &mut s);
//! assert_eq!(s.q_d, vec![0.0, 1.0]);        // sin(0), cos(0)
//! assert_eq!(s.kc, vec![0.5, 0.55]);        // 0.5 + 0.1 sin 0, 0.45 + 0.1 cos 0
//! ```

mod sinusoid;

pub use sinusoid::Sinusoid;

use serde::{Deserialize, Serialize};

/// Why a reference or envelope cannot be used. Each variant names the field.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TrajectoryError {
    /// A number is NaN or infinite.
    #[error("{field}: {value} is not a finite number")]
    NotFinite {
        /// The scenario key, e.g. `envelope.joints[1].offset`.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// The envelope can reach zero or below, so the barrier would be undefined.
    #[error(
        "{field}: the envelope must stay positive, but offset {offset} minus amplitude {amplitude} is {min} (needs > 0)"
    )]
    EnvelopeNotPositive {
        /// The scenario key of the joint's envelope.
        field: String,
        /// Its offset.
        offset: f64,
        /// Its amplitude sqrt(sin² + cos²).
        amplitude: f64,
        /// The smallest value it reaches.
        min: f64,
    },
    /// Reference and envelope disagree on the number of joints.
    #[error(
        "reference.joints has {reference} entries but envelope.joints has {envelope}; both need one per joint"
    )]
    DofMismatch {
        /// Entries in the reference.
        reference: usize,
        /// Entries in the envelope.
        envelope: usize,
    },
    /// No joints at all.
    #[error("reference.joints is empty: give one entry per joint")]
    Empty,
}

/// The desired joint trajectory, one sinusoid per joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceConfig {
    /// q_d,i(t) per joint (rad or m).
    pub joints: Vec<Sinusoid>,
}

impl ReferenceConfig {
    /// The paper's reference: q_d1 = sin(2t), q_d2 = cos(t).
    pub fn paper() -> Self {
        Self {
            joints: vec![
                Sinusoid {
                    offset: 0.0,
                    sin: 1.0,
                    cos: 0.0,
                    omega: 2.0,
                },
                Sinusoid {
                    offset: 0.0,
                    sin: 0.0,
                    cos: 1.0,
                    omega: 1.0,
                },
            ],
        }
    }
}

/// The constraint envelope on the tracking error, |Z1_i| < k_c,i(t) for t ≥ T_c.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvelopeConfig {
    /// k_c,i(t) per joint (rad or m); must stay positive.
    pub joints: Vec<Sinusoid>,
}

impl EnvelopeConfig {
    /// The paper's envelope: k_c1 = 0.5 + 0.1 sin(0.5t), k_c2 = 0.45 + 0.1 cos(0.5t).
    pub fn paper() -> Self {
        Self {
            joints: vec![
                Sinusoid {
                    offset: 0.5,
                    sin: 0.1,
                    cos: 0.0,
                    omega: 0.5,
                },
                Sinusoid {
                    offset: 0.45,
                    sin: 0.0,
                    cos: 0.1,
                    omega: 0.5,
                },
            ],
        }
    }
}

/// Everything the controller needs from the reference at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceSample {
    /// Sim time of the sample, s.
    pub t: f64,
    /// Desired position q_d.
    pub q_d: Vec<f64>,
    /// Desired velocity q̇_d.
    pub qd_d: Vec<f64>,
    /// Desired acceleration q̈_d.
    pub qdd_d: Vec<f64>,
    /// Envelope k_c.
    pub kc: Vec<f64>,
    /// Envelope rate k̇_c.
    pub kc_dot: Vec<f64>,
}

impl ReferenceSample {
    /// A zeroed sample for `dof` joints (allocate once, fill every period).
    pub fn new(dof: usize) -> Self {
        Self {
            t: 0.0,
            q_d: vec![0.0; dof],
            qd_d: vec![0.0; dof],
            qdd_d: vec![0.0; dof],
            kc: vec![0.0; dof],
            kc_dot: vec![0.0; dof],
        }
    }
}

/// A validated reference and envelope.
#[derive(Debug, Clone)]
pub struct Reference {
    q_d: Vec<Sinusoid>,
    kc: Vec<Sinusoid>,
}

impl Reference {
    /// Validates both configs (finite, same length, envelope > 0 everywhere).
    pub fn new(
        reference: &ReferenceConfig,
        envelope: &EnvelopeConfig,
    ) -> Result<Self, TrajectoryError> {
        if reference.joints.is_empty() {
            return Err(TrajectoryError::Empty);
        }
        if reference.joints.len() != envelope.joints.len() {
            return Err(TrajectoryError::DofMismatch {
                reference: reference.joints.len(),
                envelope: envelope.joints.len(),
            });
        }
        for (i, s) in reference.joints.iter().enumerate() {
            s.validate(&format!("reference.joints[{i}]"))?;
        }
        for (i, s) in envelope.joints.iter().enumerate() {
            let field = format!("envelope.joints[{i}]");
            s.validate(&field)?;
            let min = s.min_value();
            if min.is_nan() || min <= 0.0 {
                return Err(TrajectoryError::EnvelopeNotPositive {
                    field,
                    offset: s.offset,
                    amplitude: s.amplitude(),
                    min,
                });
            }
        }
        Ok(Self {
            q_d: reference.joints.clone(),
            kc: envelope.joints.clone(),
        })
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.q_d.len()
    }

    /// Fills `out` with the reference at sim time `t` (s). `out` must have
    /// been made by `ReferenceSample::new(self.dof())`.
    pub fn sample_into(&self, t: f64, out: &mut ReferenceSample) {
        out.t = t;
        for (i, s) in self.q_d.iter().enumerate() {
            let [v, d1, d2] = s.eval(t);
            out.q_d[i] = v;
            out.qd_d[i] = d1;
            out.qdd_d[i] = d2;
        }
        for (i, s) in self.kc.iter().enumerate() {
            let [v, d1, _] = s.eval(t);
            out.kc[i] = v;
            out.kc_dot[i] = d1;
        }
    }

    /// A fresh sample at `t`; allocates, for tests and tools.
    pub fn sample(&self, t: f64) -> ReferenceSample {
        let mut out = ReferenceSample::new(self.dof());
        self.sample_into(t, &mut out);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> Reference {
        Reference::new(&ReferenceConfig::paper(), &EnvelopeConfig::paper()).unwrap()
    }

    #[test]
    fn paper_reference_matches_section_iv() {
        let r = paper();
        for &t in &[0.0, 0.3, 1.7, 2.0, 9.9, 19.999] {
            let s = r.sample(t);
            let tol = 1e-15;
            assert!((s.q_d[0] - (2.0 * t).sin()).abs() < tol);
            assert!((s.q_d[1] - t.cos()).abs() < tol);
            assert!((s.qd_d[0] - 2.0 * (2.0 * t).cos()).abs() < tol);
            assert!((s.qd_d[1] + t.sin()).abs() < tol);
            assert!((s.qdd_d[0] + 4.0 * (2.0 * t).sin()).abs() < 1e-14);
            assert!((s.qdd_d[1] + t.cos()).abs() < tol);
            assert!((s.kc[0] - (0.5 + 0.1 * (0.5 * t).sin())).abs() < tol);
            assert!((s.kc[1] - (0.45 + 0.1 * (0.5 * t).cos())).abs() < tol);
            assert!((s.kc_dot[0] - 0.05 * (0.5 * t).cos()).abs() < tol);
            assert!((s.kc_dot[1] + 0.05 * (0.5 * t).sin()).abs() < tol);
        }
    }

    #[test]
    fn envelope_that_touches_zero_is_rejected_with_its_field() {
        let mut env = EnvelopeConfig::paper();
        env.joints[1].offset = 0.1;
        let err = Reference::new(&ReferenceConfig::paper(), &env).unwrap_err();
        assert!(err.to_string().starts_with("envelope.joints[1]"), "{err}");
    }

    #[test]
    fn nan_is_rejected_with_its_field() {
        let mut r = ReferenceConfig::paper();
        r.joints[0].omega = f64::NAN;
        let err = Reference::new(&r, &EnvelopeConfig::paper()).unwrap_err();
        assert_eq!(
            err.to_string(),
            "reference.joints[0].omega: NaN is not a finite number"
        );
    }

    #[test]
    fn mismatched_lengths_are_rejected() {
        let mut env = EnvelopeConfig::paper();
        env.joints.pop();
        assert_eq!(
            Reference::new(&ReferenceConfig::paper(), &env).unwrap_err(),
            TrajectoryError::DofMismatch {
                reference: 2,
                envelope: 1
            }
        );
    }
}
