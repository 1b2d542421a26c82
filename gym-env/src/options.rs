//! How an environment is made beyond its scenario: the options, their
//! defaults and checks, and the two scales derived from the arm and its
//! reference (torque per unit of action, velocity per unit of observation).

use arm_model::dynamics::Dynamics;
use controller::LawName;
use scenario::Plan;

/// Plant periods per decision by default: 20 periods of the paper's 1 kHz
/// plant are a 50 Hz policy (at 1 kHz the default discount sees 0.1 s and
/// the constraint starts 2 000 decisions in).
pub const DEFAULT_DECIMATION: u32 = 20;

/// Episode length by default, s: T_c = 2 s of the paper's scenario and
/// as long again to settle under the constraint.
pub const DEFAULT_EPISODE_S: f64 = 4.0;

/// A joint's error term (e/k_c)² counts at most this much in the reward
/// (|e| ≥ 10 k_c counts as 10 k_c): it makes a step's worst reward finite,
/// which is what an early end is charged for every step it skips.
pub const ERROR_CAP: f64 = 100.0;

/// The most plant periods per decision.
const MAX_DECIMATION: u32 = 100_000;

/// The longest episode, s (a day of simulated time).
const MAX_EPISODE_S: f64 = 86_400.0;

/// The torque scale derived from an arm is at least this fraction of a
/// joint's effort limit.
pub(crate) const EFFORT_FRACTION: f64 = 0.1;

/// The torque scale derived from an arm is at least this many times the
/// joint's largest gravity torque along the reference.
pub(crate) const GRAVITY_MARGIN: f64 = 2.0;

/// The smallest velocity scale, rad/s (or m/s): a reference that stands
/// still still has velocities to observe.
pub(crate) const MIN_VELOCITY_SCALE: f64 = 0.5;

/// Reference samples per second read to derive the scales.
const SCALE_SAMPLES_PER_S: f64 = 100.0;

/// What the action is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ActionMode {
    /// Joint torques: τ_i = clip(a_i, −1, 1) · scale_i.
    Torque,
    /// A residual on a built-in law: τ = τ_law + clip(a_i, −1, 1) ·
    /// residual_scale · scale_i.
    Residual(LawName),
}

/// How the torque of a decision is spread over its plant periods.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Smoothing {
    /// Each period adds the decision's torque: a zero-order hold.
    Hold,
    /// A ramp from the torque the last decision reached to the new one,
    /// reached at the decision's last period: a first-order hold, one
    /// decision late, with no step.
    Ramp,
    /// Each period moves the torque a fraction 1 − exp(−dt/τ) towards the
    /// decision's: a first-order low-pass of time constant τ, s.
    LowPass {
        /// The time constant τ, s.
        tau_s: f64,
    },
}

impl Smoothing {
    /// The names [`Smoothing::parse`] takes.
    pub const NAMES: [&'static str; 3] = ["hold", "ramp", "low-pass"];

    /// The smoothing named `name` (one of [`Smoothing::NAMES`]), with
    /// `tau_s` the low-pass's time constant (checked only for it).
    pub fn parse(name: &str, tau_s: f64) -> Result<Self, EnvError> {
        match name {
            "hold" => Ok(Self::Hold),
            "ramp" => Ok(Self::Ramp),
            "low-pass" if tau_s.is_finite() && tau_s > 0.0 && tau_s <= 1e3 => {
                Ok(Self::LowPass { tau_s })
            }
            "low-pass" => Err(EnvError::option(
                "smoothing_tau_s",
                tau_s,
                "must be a time constant in seconds above 0 and at most 1000",
            )),
            _ => Err(EnvError::option(
                "smoothing",
                name,
                format!("must be one of {}", Self::NAMES.join(", ")),
            )),
        }
    }

    /// Its name, as [`Smoothing::parse`] takes it.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Hold => "hold",
            Self::Ramp => "ramp",
            Self::LowPass { .. } => "low-pass",
        }
    }

    /// The low-pass's time constant, s (None for the others).
    pub fn tau_s(&self) -> Option<f64> {
        match self {
            Self::LowPass { tau_s } => Some(*tau_s),
            Self::Hold | Self::Ramp => None,
        }
    }
}

/// How an environment is made, beyond its scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvOptions {
    /// What the action is (default: torques).
    pub action: ActionMode,
    /// The residual's span as a fraction of the torque scale (default: 0.2).
    pub residual_scale: f64,
    /// Weight of the effort term mean_i a_i² of the reward (default: 0.01).
    pub effort_weight: f64,
    /// Outside safe mode, end the episode (`terminated`) once, after T_c,
    /// a joint's error passes this many times its envelope, charging the
    /// worst reward for every step it skips; None: never (default: 2).
    pub breach_factor: Option<f64>,
    /// Torque per unit of action, per joint, N m or N (default: derived
    /// from the arm: per joint, the larger of twice its largest gravity
    /// torque along the reference and a tenth of its effort limit, at most
    /// that limit).
    pub torque_scale: Option<Vec<f64>>,
    /// Plant periods per decision: the action is held that long (default:
    /// [`DEFAULT_DECIMATION`]).
    pub decimation: u32,
    /// Safe-RL mode: no early end on a breach; the cost is reported, the
    /// reward does not count it (default: false).
    pub safe: bool,
    /// Scale the observation: errors over k_c, velocities over the
    /// velocity scale (default: true; false gives the raw quantities).
    pub scale_obs: bool,
    /// How a decision's torque is spread over its plant periods (default:
    /// held, [`Smoothing::Hold`]).
    pub smoothing: Smoothing,
    /// Weight of the action-rate term mean_i (a_i − a_i,prev)² of the
    /// reward, a the clipped actions of this decision and the last
    /// (default: 0).
    pub action_rate_weight: f64,
    /// The last clipped action ends the observation (default: false): a
    /// ramp or a low-pass makes the torque depend on it.
    pub observe_action: bool,
}

impl Default for EnvOptions {
    fn default() -> Self {
        Self {
            action: ActionMode::Torque,
            residual_scale: 0.2,
            effort_weight: 0.01,
            breach_factor: Some(2.0),
            torque_scale: None,
            decimation: DEFAULT_DECIMATION,
            safe: false,
            scale_obs: true,
            smoothing: Smoothing::Hold,
            action_rate_weight: 0.0,
            observe_action: false,
        }
    }
}

/// Why an environment cannot be made or reset.
#[derive(Debug, thiserror::Error)]
pub enum EnvError {
    /// An option out of range.
    #[error("{name} = {value}: {why}")]
    Option {
        /// The option, as the caller spells it.
        name: String,
        /// Its value, as given.
        value: String,
        /// What it must be.
        why: String,
    },
    /// The scenario drawn for a seed is unusable.
    #[error("{0}")]
    Scenario(#[from] scenario::ScenarioError),
    /// The plant cannot be built.
    #[error("plant: {0}")]
    Plant(#[from] plant_rapier::PlantError),
    /// The base law cannot be built.
    #[error("base law: {0}")]
    Controller(#[from] controller::ControllerError),
    /// The vector form's threads cannot be started.
    #[error("num_threads: cannot start the threads: {0}")]
    Threads(#[from] rayon::ThreadPoolBuildError),
}

impl EnvError {
    /// An option error.
    pub(crate) fn option(
        name: &str,
        value: impl std::fmt::Display,
        why: impl Into<String>,
    ) -> Self {
        Self::Option {
            name: name.to_string(),
            value: cut(&value.to_string()),
            why: why.into(),
        }
    }
}

/// A value quoted in a message, cut to 80 characters.
fn cut(s: &str) -> String {
    match s.char_indices().nth(80) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

/// `episode_s` checked: a positive, finite length up to a day.
pub fn check_episode_s(v: f64) -> Result<f64, EnvError> {
    if v.is_finite() && v > 0.0 && v <= MAX_EPISODE_S {
        Ok(v)
    } else {
        Err(EnvError::option(
            "episode_s",
            v,
            format!("must be a length in seconds above 0 and at most {MAX_EPISODE_S}"),
        ))
    }
}

impl EnvOptions {
    /// Positive checks, so that NaN fails too.
    pub(crate) fn check(&self) -> Result<(), EnvError> {
        // The residual times the largest torque scale must stay a number.
        if !(self.residual_scale.is_finite()
            && self.residual_scale > 0.0
            && self.residual_scale <= 1e3)
        {
            return Err(EnvError::option(
                "residual_scale",
                self.residual_scale,
                "must be a number above 0 and at most 1000",
            ));
        }
        if !(self.effort_weight.is_finite() && (0.0..=1e6).contains(&self.effort_weight)) {
            return Err(EnvError::option(
                "effort_weight",
                self.effort_weight,
                "must be a number from 0 to 1e6",
            ));
        }
        if !(self.action_rate_weight.is_finite() && (0.0..=1e6).contains(&self.action_rate_weight))
        {
            return Err(EnvError::option(
                "action_rate_weight",
                self.action_rate_weight,
                "must be a number from 0 to 1e6",
            ));
        }
        if let Some(tau) = self.smoothing.tau_s() {
            Smoothing::parse("low-pass", tau)?;
        }
        if let Some(f) = self.breach_factor
            && !(f.is_finite() && (1.0..=1e6).contains(&f))
        {
            return Err(EnvError::option(
                "breach_factor",
                f,
                "must be a number from 1 to 1e6, or None",
            ));
        }
        if !(1..=MAX_DECIMATION).contains(&self.decimation) {
            return Err(EnvError::option(
                "decimation",
                self.decimation,
                format!("must be a whole number of plant periods from 1 to {MAX_DECIMATION}"),
            ));
        }
        Ok(())
    }
}

/// The torque per unit of action: `given`, else derived from the arm.
pub(crate) fn torque_scale(plan: &Plan, given: Option<&[f64]>) -> Result<Vec<f64>, EnvError> {
    let m = &plan.robot.model;
    let n = m.dof();
    let names = m.joint_names();
    let scale = match given {
        Some(g) => {
            if g.len() != n {
                return Err(EnvError::option(
                    "torque_scale",
                    format!("{g:?}"),
                    format!(
                        "has {} values; {} has {n} controlled joints ({})",
                        g.len(),
                        plan.robot.label(),
                        names.join(", ")
                    ),
                ));
            }
            if let Some(i) = g
                .iter()
                .position(|s| !(s.is_finite() && *s > 0.0 && *s <= 1e9))
            {
                return Err(EnvError::option(
                    &format!("torque_scale[{i}]"),
                    g[i],
                    format!(
                        "joint {} needs a torque above 0 and at most 1e9 (N m or N)",
                        names[i]
                    ),
                ));
            }
            g.to_vec()
        }
        None => derived_torque_scale(plan)?,
    };
    Ok(scale)
}

/// The rule: per joint, the larger of [`GRAVITY_MARGIN`] × its largest
/// gravity torque over the scenario's reference and [`EFFORT_FRACTION`] of
/// its effort limit, and never above that limit (the scenario's
/// `plant.effort_limit`, else the URDF's). A joint with neither a limit
/// nor a gravity load has no scale: the caller must give one.
fn derived_torque_scale(plan: &Plan) -> Result<Vec<f64>, EnvError> {
    let m = &plan.robot.model;
    let n = m.dof();
    let names = m.joint_names();
    let limits: Vec<f64> = match &plan.scenario.plant.effort_limit {
        Some(l) => l.resolve("plant.effort_limit", n)?,
        None => m
            .actuated
            .iter()
            .map(|&j| m.joints[j].effort.unwrap_or(f64::INFINITY))
            .collect(),
    };
    let hold = gravity_hold(plan);
    let mut scale = Vec::with_capacity(n);
    for i in 0..n {
        let from_limit = if limits[i].is_finite() {
            EFFORT_FRACTION * limits[i]
        } else {
            0.0
        };
        let s = (GRAVITY_MARGIN * hold[i]).max(from_limit).min(limits[i]);
        if !(s.is_finite() && s > 0.0) {
            return Err(EnvError::option(
                "torque_scale",
                "None",
                format!(
                    "joint {} of {} has no effort limit and no gravity load to derive a scale \
                     from: give torque_scale=[...] (N m or N per unit of action) or set \
                     plant.effort_limit",
                    names[i],
                    plan.robot.label()
                ),
            ));
        }
        scale.push(s);
    }
    Ok(scale)
}

/// Each joint's largest |G(q_d(t))| over the reference, sampled
/// [`SCALE_SAMPLES_PER_S`] times a second (and at the end).
fn gravity_hold(plan: &Plan) -> Vec<f64> {
    let m = &plan.robot.model;
    let mut dynamics = Dynamics::new(m, plan.scenario.plant.mass_scale);
    let mut hold = vec![0.0_f64; m.dof()];
    for_reference_samples(plan, |r| {
        for (h, g) in hold.iter_mut().zip(dynamics.gravity(&r.q_d)) {
            if g.is_finite() {
                *h = h.max(g.abs());
            }
        }
    });
    hold
}

/// Each joint's velocity scale: its largest |q̇_d| over the reference,
/// at least [`MIN_VELOCITY_SCALE`].
pub(crate) fn velocity_scale(plan: &Plan) -> Vec<f64> {
    let mut v = vec![MIN_VELOCITY_SCALE; plan.robot.model.dof()];
    for_reference_samples(plan, |r| {
        for (v, qd) in v.iter_mut().zip(&r.qd_d) {
            if qd.is_finite() {
                *v = v.max(qd.abs());
            }
        }
    });
    v
}

fn for_reference_samples(plan: &Plan, mut f: impl FnMut(&trajectory::ReferenceSample)) {
    let duration = plan.steps as f64 * plan.dt();
    let count = (duration * SCALE_SAMPLES_PER_S).ceil().max(1.0) as u64;
    let mut r = trajectory::ReferenceSample::new(plan.reference.dof());
    for j in 0..=count {
        plan.reference
            .sample_into(duration * j as f64 / count as f64, &mut r);
        f(&r);
    }
}
