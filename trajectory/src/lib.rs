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
mod samples;
mod signal;
mod sinusoid;
mod waypoints;

pub use machine::TrajectoryMachine;
pub use samples::{MAX_ROWS, Samples};
pub use signal::{Ramp, Signal, Sine, Step};
pub use sinusoid::Sinusoid;
pub use waypoints::Waypoint;

use samples::Spline;

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
    /// than the state, so a slower reference is held between samples.
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
fn paper_reference_joints() -> Vec<Signal> {
    ReferenceConfig::paper().joints
}

fn paper_envelope_joints() -> Vec<Signal> {
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

/// Where q_d comes from.
#[derive(Debug, Clone)]
enum Desired {
    /// One signal per joint.
    Signals(Vec<Signal>),
    /// Minimum-jerk moves through postures.
    Waypoints(Vec<Waypoint>),
    /// A spline through a file's samples.
    Samples(Spline),
}

impl Desired {
    fn dof(&self) -> usize {
        match self {
            Self::Signals(s) => s.len(),
            Self::Waypoints(w) => w[0].q.len(),
            Self::Samples(s) => s.columns(),
        }
    }

    fn eval(&self, i: usize, t: f64) -> [f64; 3] {
        match self {
            Self::Signals(s) => s[i].eval(t),
            Self::Waypoints(w) => waypoints::eval(w, i, t),
            Self::Samples(s) => s.eval(i, t),
        }
    }

    /// The smallest and largest value joint `i` takes (bounds for signals).
    fn range(&self, i: usize) -> (f64, f64) {
        match self {
            Self::Signals(s) => (s[i].min_value(), s[i].max_value()),
            Self::Waypoints(w) => w
                .iter()
                .map(|p| p.q[i])
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                }),
            Self::Samples(s) => s.range(i),
        }
    }
}

/// Where k_c comes from.
#[derive(Debug, Clone)]
enum Envelope {
    /// One signal per joint.
    Signals(Vec<Signal>),
    /// A spline through a file's samples.
    Samples(Spline),
    /// The distance from q_d to the nearer joint limit.
    Limits(Vec<(f64, f64)>),
}

/// A validated reference and envelope.
#[derive(Debug, Clone)]
pub struct Reference {
    q_d: Desired,
    kc: Envelope,
}

/// The samples of a `file`, which the scenario loader must have read.
fn loaded<'a>(
    file: &Option<String>,
    samples: &'a Option<Samples>,
    field: &str,
) -> Result<Option<&'a Samples>, TrajectoryError> {
    match (file, samples) {
        (_, Some(s)) => {
            s.validate(&format!("{field}.samples"))?;
            Ok(Some(s))
        }
        (Some(f), None) => Err(TrajectoryError::Invalid {
            field: format!("{field}.file"),
            reason: format!("{f:?} was not read (the scenario loader reads it)"),
        }),
        (None, None) => Ok(None),
    }
}

impl ReferenceConfig {
    /// Checks that every number is finite and that one source is given.
    pub fn validate(&self) -> Result<(), TrajectoryError> {
        self.desired().map(|_| ())
    }

    /// Joints the reference drives.
    pub fn dof(&self) -> usize {
        self.desired().map_or(self.joints.len(), |d| d.dof())
    }

    fn desired(&self) -> Result<Desired, TrajectoryError> {
        let samples = loaded(&self.file, &self.samples, "reference")?;
        let sources = usize::from(!self.waypoints.is_empty()) + usize::from(samples.is_some());
        if sources > 1 || (sources == 1 && self.joints != paper_reference_joints()) {
            return Err(TrajectoryError::Invalid {
                field: "reference".into(),
                reason: "give one of `joints`, `waypoints` or `file`, not several".into(),
            });
        }
        let desired = if !self.waypoints.is_empty() {
            waypoints::validate(&self.waypoints)?;
            Desired::Waypoints(self.waypoints.clone())
        } else if let Some(s) = samples {
            Desired::Samples(Spline::new(s))
        } else {
            for (i, s) in self.joints.iter().enumerate() {
                s.validate(&format!("reference.joints[{i}]"))?;
            }
            Desired::Signals(self.joints.clone())
        };
        match desired.dof() {
            0 => Err(TrajectoryError::Empty),
            n if n > wire::MAX_DOF => Err(TrajectoryError::TooManyJoints(n)),
            _ => Ok(desired),
        }
    }
}

impl EnvelopeConfig {
    /// Joints the envelope covers (0 with `from_limits`: it covers all).
    pub fn dof(&self) -> usize {
        match &self.samples {
            Some(s) => s.values.len(),
            None => self.joints.len(),
        }
    }

    /// The envelope, checked positive.
    fn envelope(&self) -> Result<Envelope, TrajectoryError> {
        if let Some(s) = loaded(&self.file, &self.samples, "envelope")? {
            if self.joints != paper_envelope_joints() {
                return Err(TrajectoryError::Invalid {
                    field: "envelope".into(),
                    reason: "give `joints` or `file`, not both".into(),
                });
            }
            let spline = Spline::new(s);
            for (c, name) in s.columns.iter().enumerate() {
                let (min, _) = spline.range(c);
                if min.is_nan() || min <= 0.0 {
                    return Err(TrajectoryError::Invalid {
                        field: format!("envelope.file ({}, column '{name}')", s.source),
                        reason: format!("the envelope must stay positive, but reaches {min}"),
                    });
                }
            }
            return Ok(Envelope::Samples(spline));
        }
        for (i, s) in self.joints.iter().enumerate() {
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
        Ok(Envelope::Signals(self.joints.clone()))
    }
}

impl Reference {
    /// Validates both configs (finite, same length, envelope > 0 everywhere).
    /// Without `from_limits` only; see [`Reference::with_limits`].
    pub fn new(
        reference: &ReferenceConfig,
        envelope: &EnvelopeConfig,
    ) -> Result<Self, TrajectoryError> {
        let q_d = reference.desired()?;
        if q_d.dof() != envelope.dof() {
            return Err(TrajectoryError::DofMismatch {
                reference: q_d.dof(),
                envelope: envelope.dof(),
            });
        }
        Ok(Self {
            q_d,
            kc: envelope.envelope()?,
        })
    }

    /// Like [`Reference::new`], but with `envelope.from_limits` the envelope
    /// is taken from `limits` (per joint, named by `names`).
    pub fn with_limits(
        reference: &ReferenceConfig,
        envelope: &EnvelopeConfig,
        limits: &[Option<(f64, f64)>],
        names: &[String],
    ) -> Result<Self, TrajectoryError> {
        if !envelope.from_limits {
            return Self::new(reference, envelope);
        }
        let q_d = reference.desired()?;
        let mut bounds = Vec::with_capacity(limits.len());
        for (i, (lim, name)) in limits.iter().zip(names).enumerate() {
            let Some((lo, hi)) = *lim else {
                return Err(TrajectoryError::NoLimits {
                    joint: name.clone(),
                });
            };
            if i < q_d.dof() {
                let (min, max) = q_d.range(i);
                if !(min > lo && max < hi) {
                    return Err(TrajectoryError::OutsideLimits {
                        field: format!("reference.joints[{i}]"),
                        joint: name.clone(),
                        lo,
                        hi,
                        min,
                        max,
                    });
                }
            }
            bounds.push((lo, hi));
        }
        if q_d.dof() != bounds.len() {
            return Err(TrajectoryError::DofMismatch {
                reference: q_d.dof(),
                envelope: bounds.len(),
            });
        }
        Ok(Self {
            q_d,
            kc: Envelope::Limits(bounds),
        })
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.q_d.dof()
    }

    /// The smallest and largest q_d of joint `i` (bounds for signals; the
    /// spline checked between its samples).
    pub fn range(&self, i: usize) -> (f64, f64) {
        self.q_d.range(i)
    }

    /// Fills `out` with the reference at sim time `t` (s). `out` must have
    /// been made by `ReferenceSample::new(self.dof())`.
    pub fn sample_into(&self, t: f64, out: &mut ReferenceSample) {
        out.t = t;
        for i in 0..self.dof() {
            let [v, d1, d2] = self.q_d.eval(i, t);
            out.q_d[i] = v;
            out.qd_d[i] = d1;
            out.qdd_d[i] = d2;
        }
        match &self.kc {
            Envelope::Signals(kc) => {
                for (i, s) in kc.iter().enumerate() {
                    let [v, d1, _] = s.eval(t);
                    out.kc[i] = v;
                    out.kc_dot[i] = d1;
                }
            }
            Envelope::Samples(spline) => {
                for i in 0..spline.columns() {
                    let [v, d1, _] = spline.eval(i, t);
                    out.kc[i] = v;
                    out.kc_dot[i] = d1;
                }
            }
            Envelope::Limits(bounds) => {
                for (i, (lo, hi)) in bounds.iter().enumerate() {
                    let (up, down) = (hi - out.q_d[i], out.q_d[i] - lo);
                    // The nearer limit binds; k̇_c follows it.
                    if up <= down {
                        out.kc[i] = up;
                        out.kc_dot[i] = -out.qd_d[i];
                    } else {
                        out.kc[i] = down;
                        out.kc_dot[i] = out.qd_d[i];
                    }
                }
            }
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
