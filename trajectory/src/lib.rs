//! The reference trajectory q_d(t) and the constraint envelope k_c(t).
//!
//! Where it sits: at the head of the data flow, feeding the controller q_d,
//! q̇_d, q̈_d, k_c and k̇_c. The core ([`Reference::sample_into`]) is a pure
//! function of sim time: no clock, no I/O, so a log alone can reproduce it.
//! [`TrajectoryMachine`] turns it into wire samples; the trajectory node
//! ([`node`]) publishes them, and `testbed sim` calls the same machine.
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

mod machine;
pub mod node;
mod reference;
mod samples;
mod signal;
mod sinusoid;
mod waypoints;

pub use machine::{TrajectoryMachine, TrajectoryMachineConfig};
pub use reference::{Reference, ReferenceSample};
pub use samples::{MAX_ROWS, Samples};
pub use signal::{Ramp, Signal, Sine, Step};
pub use sinusoid::Sinusoid;
pub use waypoints::Waypoint;

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
    /// The envelope is to come from joint limits, but a joint has none.
    #[error(
        "envelope.from_limits: joint '{joint}' has no position limits (continuous or unlimited)"
    )]
    NoLimits {
        /// The joint.
        joint: String,
    },
    /// With the envelope from the limits, the reference must stay inside them.
    #[error(
        "{field}: with envelope.from_limits the reference must stay inside joint '{joint}' limits [{lo}, {hi}], but it spans [{min}, {max}]"
    )]
    OutsideLimits {
        /// The reference's key.
        field: String,
        /// The joint.
        joint: String,
        /// Its lower limit.
        lo: f64,
        /// Its upper limit.
        hi: f64,
        /// The reference's smallest value.
        min: f64,
        /// The reference's largest value.
        max: f64,
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
    /// A value that is finite but not allowed.
    #[error("{field}: {reason}")]
    Invalid {
        /// The scenario key.
        field: String,
        /// What is wrong and what to give.
        reason: String,
    },
    /// A trajectory file's cell.
    #[error("{file}: row {row}, column {column} ('{name}'): {reason}")]
    Csv {
        /// The file.
        file: String,
        /// Its row, from 1 (the header is row 1).
        row: usize,
        /// Its column, from 1.
        column: usize,
        /// The column's name in the header.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// More joints than a sample carries.
    #[error(
        "reference.joints has {0} entries; a reference sample carries at most {max} joints (lock the others in [plant.lock])",
        max = wire::MAX_DOF
    )]
    TooManyJoints(usize),
}

/// The desired joint trajectory, one sinusoid per joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceConfig {
    /// q_d,i(t) per joint (rad or m; default: the paper's two).
    #[serde(default = "paper_reference_joints")]
    pub joints: Vec<Signal>,
    /// Or: minimum-jerk moves through these postures (instead of `joints`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub waypoints: Vec<Waypoint>,
    /// Or: a CSV file of `t` and one column per joint, relative to the
    /// scenario file (instead of `joints`); the scenario loader reads it
    /// into `samples`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// The samples of `file`, as read (or given inline).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<Samples>,
    /// Rate at which the trajectory publishes samples, Hz (default: unset,
    /// the control rate). The controller uses the newest sample not later
    /// than the state, so a slower reference is held between samples; a
    /// faster one is refused ([`ReferenceConfig::rate_fault`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<f64>,
    /// In real time, how far ahead of its time each sample is published, s
    /// (default [`DEFAULT_HORIZON_S`]). The reference is a known function
    /// of time, so a trajectory process the machine delays by less than
    /// this never makes the controller use a stale sample; 0 publishes each
    /// sample just in time, as a live planner would.
    #[serde(default = "default_horizon")]
    pub horizon_s: f64,
}

/// The real-time publishing horizon of a scenario that sets none, s: far
/// longer than the stalls a loaded machine gives a process it schedules
/// (the trajectory also runs under SCHED_FIFO), far inside a subscriber's
/// buffer.
pub const DEFAULT_HORIZON_S: f64 = 0.05;

/// Reference samples a horizon may span: half a subscriber's buffer.
pub const MAX_HORIZON_SAMPLES: f64 = (wire::SUBSCRIBER_BUFFER / 2) as f64;

fn default_horizon() -> f64 {
    DEFAULT_HORIZON_S
}

impl ReferenceConfig {
    /// What `rate_hz` must be beside a control rate of `control_rate_hz`
    /// (None: it is fine). At most the control rate: the controller takes
    /// one sample a step, the newest at or before the state, so faster
    /// samples are never used; in real time they only crowd the machine
    /// (50 kHz against 1 kHz starved the logger, which was then blamed as
    /// not heard from).
    pub fn rate_fault(&self, control_rate_hz: f64) -> Option<String> {
        let r = self.rate_hz?;
        (r > control_rate_hz).then(|| {
            format!(
                "at most the control rate, rate_hz = {control_rate_hz} Hz: the controller takes one reference sample a control step, so a faster reference only sends samples no step uses (and in real time crowds out the other nodes)"
            )
        })
    }

    /// What `horizon_s` must be when the reference is published at its own
    /// `rate_hz` or, unset, at `control_rate_hz`; None when it is.
    pub fn horizon_fault(&self, control_rate_hz: f64) -> Option<String> {
        let rate = self.rate_hz.unwrap_or(control_rate_hz);
        let h = self.horizon_s;
        (!(h >= 0.0 && h * rate <= MAX_HORIZON_SAMPLES)).then(|| {
            format!(
                "seconds from 0 to {} (at most {MAX_HORIZON_SAMPLES} reference samples ahead)",
                MAX_HORIZON_SAMPLES / rate
            )
        })
    }

    /// The horizon as the real-time trajectory publishes ahead, ns: a whole
    /// number of reference periods of `reference_period_ns`, rounded up.
    pub fn horizon_ns(&self, reference_period_ns: u64) -> u64 {
        let h = (self.horizon_s * 1e9).round() as u64;
        h.div_ceil(reference_period_ns) * reference_period_ns
    }

    /// The paper's reference: q_d1 = sin(2t), q_d2 = cos(t).
    pub fn paper() -> Self {
        Self {
            joints: vec![
                Sinusoid {
                    offset: 0.0,
                    sin: 1.0,
                    cos: 0.0,
                    omega: 2.0,
                }
                .into(),
                Sinusoid {
                    offset: 0.0,
                    sin: 0.0,
                    cos: 1.0,
                    omega: 1.0,
                }
                .into(),
            ],
            waypoints: Vec::new(),
            file: None,
            samples: None,
            rate_hz: None,
            horizon_s: DEFAULT_HORIZON_S,
        }
    }
}

/// A table that leaves `joints` out takes the paper's (every key is optional).
pub(crate) fn paper_reference_joints() -> Vec<Signal> {
    ReferenceConfig::paper().joints
}

pub(crate) fn paper_envelope_joints() -> Vec<Signal> {
    EnvelopeConfig::paper().joints
}

/// The constraint envelope on the tracking error, |Z1_i| < k_c,i(t) for t ≥ T_c.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvelopeConfig {
    /// k_c,i(t) per joint (rad or m; default: the paper's two); must stay
    /// positive. Ignored with `from_limits`.
    #[serde(default = "paper_envelope_joints")]
    pub joints: Vec<Signal>,
    /// Or: a CSV file of `t` and one k_c column per joint, relative to the
    /// scenario file (instead of `joints`); read into `samples`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// The samples of `file`, as read (or given inline).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<Samples>,
    /// Take the envelope from the robot's joint limits, as in the paper's
    /// Section III: k_c,i(t) = min(upper_i − q_d,i(t), q_d,i(t) − lower_i)
    /// (default: false).
    #[serde(default)]
    pub from_limits: bool,
}

impl EnvelopeConfig {
    /// The paper's envelope: k_c1 = 0.5 + 0.1 sin(0.5t), k_c2 = 0.45 + 0.1 cos(0.5t).
    pub fn paper() -> Self {
        Self {
            from_limits: false,
            file: None,
            samples: None,
            joints: vec![
                Sinusoid {
                    offset: 0.5,
                    sin: 0.1,
                    cos: 0.0,
                    omega: 0.5,
                }
                .into(),
                Sinusoid {
                    offset: 0.45,
                    sin: 0.0,
                    cos: 0.1,
                    omega: 0.5,
                }
                .into(),
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> Reference {
        Reference::new(&ReferenceConfig::paper(), &EnvelopeConfig::paper()).unwrap()
    }

    /// The horizon's check and its conversion to whole reference periods
    /// live here, where the reference is published.
    #[test]
    fn the_horizon_is_checked_and_rounded_up_to_whole_periods() {
        let mut r = ReferenceConfig::paper();
        assert_eq!(r.horizon_fault(1000.0), None);
        assert_eq!(r.horizon_ns(1_000_000), 50_000_000);
        r.horizon_s = 0.0505;
        assert_eq!(r.horizon_ns(1_000_000), 51_000_000);
        r.horizon_s = -1.0;
        assert!(r.horizon_fault(1000.0).is_some());
        r.horizon_s = f64::NAN;
        assert!(r.horizon_fault(1000.0).is_some());
        // At a 100 Hz reference, the samples allow a horizon 10× longer.
        r.horizon_s = MAX_HORIZON_SAMPLES / 1000.0 * 5.0;
        assert!(r.horizon_fault(1000.0).is_some());
        r.rate_hz = Some(100.0);
        assert_eq!(r.horizon_fault(1000.0), None);
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
    fn envelope_from_limits_is_the_distance_to_the_nearer_limit() {
        let env = EnvelopeConfig {
            joints: vec![],
            from_limits: true,
            file: None,
            samples: None,
        };
        let names = ["a".to_string(), "b".to_string()];
        let r = Reference::with_limits(
            &ReferenceConfig::paper(),
            &env,
            &[Some((-1.5, 1.5)), Some((-2.0, 1.2))],
            &names,
        )
        .unwrap();
        for &t in &[0.0, 0.4, 1.0, 3.3] {
            let s = r.sample(t);
            assert!((s.kc[0] - (1.5 - (2.0 * t).sin().abs())).abs() < 1e-12);
            let expect = (1.2 - t.cos()).min(t.cos() + 2.0);
            assert!((s.kc[1] - expect).abs() < 1e-12);
            // k̇_c is the derivative of the active branch.
            let h = 1e-6;
            let fd = (r.sample(t + h).kc[1] - r.sample(t - h).kc[1]) / (2.0 * h);
            assert!((s.kc_dot[1] - fd).abs() < 1e-6, "t = {t}");
        }
        let err = Reference::with_limits(
            &ReferenceConfig::paper(),
            &env,
            &[Some((-0.5, 0.5)), None],
            &names,
        )
        .unwrap_err();
        assert!(
            err.to_string()
                .contains("must stay inside joint 'a' limits"),
            "{err}"
        );
        let err = Reference::with_limits(
            &ReferenceConfig::paper(),
            &env,
            &[Some((-2.0, 2.0)), None],
            &names,
        )
        .unwrap_err();
        assert!(
            err.to_string().contains("joint 'b' has no position limits"),
            "{err}"
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
