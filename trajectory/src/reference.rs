//! The validated reference and envelope ([`Reference`]) and their value at
//! any sim time ([`Reference::sample_into`]): what the scenario's
//! `[reference]` and `[envelope]` tables (in `lib.rs`) become once checked.

use crate::samples::{Samples, Spline};
use crate::{
    EnvelopeConfig, ReferenceConfig, Signal, TrajectoryError, Waypoint, paper_envelope_joints,
    paper_reference_joints, waypoints,
};

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
