//! Plant settings, as read from a scenario's `[plant]` table and its
//! sub-tables: what the arm does that the controller does not know.
//! Every effect is off unless the scenario turns it on.

use serde::{Deserialize, Serialize};

use crate::{EngineName, Locks, PlantError};

mod actuator;
mod contact;
mod per_joint;

pub use actuator::{ActuatorConfig, Harmonic, JointActuator, Spring};
pub use contact::{ContactConfig, ContactObject, Obstacle, ShapeName};
pub use per_joint::PerJoint;

/// How the plant integrates, and the effects it adds on top of the rigid
/// body dynamics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlantConfig {
    /// What integrates the rigid-body dynamics (default: `"articulated"`).
    pub engine: EngineName,
    /// Integrator steps per control period (default: 1 for `articulated`,
    /// 6 for `rapier`). The articulated engine is fourth order: at a 1 ms
    /// period one step keeps the one-step mean acceleration within 1e-8 of
    /// a converged RK4 reference. Rapier's integrator is first order: 6
    /// keeps a 5 s passive swing within 4e-5 rad of it and the one-step
    /// acceleration within 1.5e-3 (8: 2.9e-5 and 1.2e-3, at a third more
    /// cost per step).
    pub substeps: Option<u32>,
    /// Gravity vector in the URDF's world frame (default: [0, 0, -9.81], m/s²).
    pub gravity: [f64; 3],
    /// Clip each joint's torque to its effort limit (default: true).
    pub saturate: bool,
    /// Effort limit per joint, N m (N for prismatic joints); replaces the
    /// URDF's `<limit effort>` (default: unset, the URDF's).
    pub effort_limit: Option<PerJoint>,
    /// Apply the URDF's `<dynamics damping friction>` to its joints
    /// (default: true).
    pub urdf_dynamics: bool,
    /// Motor armature (rotor inertia × gear ratio²) per controlled joint,
    /// which URDFs omit, kg m² (kg for prismatic joints) (default: 0); an
    /// MJCF joint's own `armature` is added to it.
    pub armature: PerJoint,
    /// Joint friction.
    pub friction: FrictionConfig,
    /// A payload mass fixed to a link.
    pub payload: Option<PayloadConfig>,
    /// The disturbance d(t) of the paper's eq. 1, added to the joint torques.
    pub disturbance: DisturbanceConfig,
    /// What the joint sensors report.
    pub sensor: SensorConfig,
    /// What happens to a command between the controller and the motors.
    pub actuation: ActuationConfig,
    /// The motors and transmissions: torque lag and slew, cogging, series
    /// elasticity and backlash. Unwritten when off, so that scenarios'
    /// identities keep.
    #[serde(skip_serializing_if = "ActuatorConfig::is_off")]
    pub actuator: ActuatorConfig,
    /// Contact between the links' `<collision>` primitives and obstacles
    /// (`engine = "rapier"` only). Unwritten when off.
    #[serde(skip_serializing_if = "ContactConfig::is_off")]
    pub contact: ContactConfig,
    /// Joints held still, by URDF name and position (rad or m):
    /// `[plant.lock]` with `finger_joint1 = 0.02`. A locked joint is
    /// simulated as fixed and is not controlled; a joint that mimics it is
    /// held where the coupling puts it (default: none; the default scenario
    /// of an arm locks its gripper and finger joints).
    pub lock: Locks,
    /// Every link's mass and inertia times this, in the plant only: model
    /// error the controller does not know of (default: 1, the URDF's).
    /// Unwritten at 1 so that scenarios' identities (sweep keys) keep.
    #[serde(skip_serializing_if = "is_one")]
    pub mass_scale: f64,
}

fn is_one(x: &f64) -> bool {
    *x == 1.0
}

impl Default for PlantConfig {
    fn default() -> Self {
        Self {
            engine: EngineName::default(),
            substeps: None,
            gravity: [0.0, 0.0, -9.81],
            saturate: true,
            effort_limit: None,
            friction: FrictionConfig::default(),
            payload: None,
            disturbance: DisturbanceConfig::default(),
            sensor: SensorConfig::default(),
            actuation: ActuationConfig::default(),
            actuator: ActuatorConfig::default(),
            contact: ContactConfig::default(),
            lock: Locks::new(),
            urdf_dynamics: true,
            armature: PerJoint::default(),
            mass_scale: 1.0,
        }
    }
}

/// Viscous plus Coulomb friction at each joint:
/// τ_f = −(b q̇ + F_c tanh(q̇ / v_s)), smoothed near zero velocity so that
/// the dynamics stay continuous.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FrictionConfig {
    /// Viscous coefficient b, N m s/rad (default: 0).
    pub viscous: PerJoint,
    /// Coulomb level F_c, N m (default: 0).
    pub coulomb: PerJoint,
    /// Velocity v_s at which the Coulomb term reaches tanh(1) ≈ 76 % of F_c
    /// (default: 0.01, rad/s).
    pub smoothing_velocity: f64,
}

impl Default for FrictionConfig {
    fn default() -> Self {
        Self {
            viscous: PerJoint::default(),
            coulomb: PerJoint::default(),
            smoothing_velocity: 0.01,
        }
    }
}

/// A point mass fixed to a link, from a given time on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PayloadConfig {
    /// The URDF link that carries it (a link merged by a fixed joint is fine).
    pub link: String,
    /// Its mass, kg.
    pub mass: f64,
    /// Where it sits in the link's frame, m (default: the link origin).
    pub offset: [f64; 3],
    /// When it is picked up, s (default: 0, carried from the start).
    pub attach_at_s: f64,
}

impl Default for PayloadConfig {
    fn default() -> Self {
        Self {
            link: String::new(),
            mass: 0.0,
            offset: [0.0; 3],
            attach_at_s: 0.0,
        }
    }
}

/// The bounded disturbance d(t), per joint, as the sum of four parts:
/// a constant, a step, a sinusoid, and band-limited noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DisturbanceConfig {
    /// Constant part, N m (signed: one number or one per joint).
    pub constant: PerJoint,
    /// Step part: added from `step_at_s` on, N m (signed).
    pub step: PerJoint,
    /// Time of the step, s (default: 0).
    pub step_at_s: f64,
    /// Amplitude of the sinusoid, N m (signed).
    pub sin_amplitude: PerJoint,
    /// Its angular frequency, rad/s (default: 1).
    pub sin_omega: f64,
    /// Standard deviation of the noise, N m (default: 0, off).
    pub noise_std: PerJoint,
    /// Noise bandwidth: first-order low-pass corner, Hz (default: 10). The
    /// noise is clipped at 3 standard deviations so that d stays bounded,
    /// as the paper assumes.
    pub noise_bandwidth_hz: f64,
}

impl Default for DisturbanceConfig {
    fn default() -> Self {
        Self {
            constant: PerJoint::default(),
            step: PerJoint::default(),
            step_at_s: 0.0,
            sin_amplitude: PerJoint::default(),
            sin_omega: 1.0,
            noise_std: PerJoint::default(),
            noise_bandwidth_hz: 10.0,
        }
    }
}

/// What the joint sensors report: q and q̇ plus Gaussian noise, and q
/// quantised to an encoder's resolution.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorConfig {
    /// Standard deviation of the noise on q, rad (default: 0).
    pub q_noise_std: PerJoint,
    /// Standard deviation of the noise on q̇, rad/s (default: 0).
    pub qd_noise_std: PerJoint,
    /// Encoder resolution: q is reported as a whole number of these, rad
    /// (default: 0, no quantisation; a 4096-count encoder is 2π/4096 ≈ 0.00153).
    pub q_resolution: PerJoint,
}

/// What happens to a command on its way to the motors.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ActuationConfig {
    /// The command computed from state k is applied over period k + N
    /// (default: 0).
    pub delay_periods: u32,
    /// Probability that a command is lost; the motors then hold the last
    /// one received (default: 0).
    pub drop_probability: f64,
}

/// A number as a message shows it: 1e308, not its 309 digits (nor 1e-300
/// as 300 zeros).
pub(super) fn short(x: f64) -> String {
    if x.is_finite() && (x.abs() >= 1e15 || (x != 0.0 && x.abs() < 1e-6)) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

fn invalid(key: &str, value: impl ToString, need: impl ToString) -> PlantError {
    PlantError::InvalidConfig {
        key: key.to_string(),
        value: value.to_string(),
        need: need.to_string(),
    }
}

fn check_finite(key: &str, v: &[f64]) -> Result<(), PlantError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(invalid(
            &format!("{key}[{i}]"),
            v[i].to_string(),
            "a finite number",
        )),
        None => Ok(()),
    }
}

impl PlantConfig {
    /// Integrator steps per period: the scenario's, or the engine's default.
    pub fn substeps_or_default(&self) -> u32 {
        self.substeps.unwrap_or(match self.engine {
            EngineName::Articulated => 1,
            EngineName::Rapier => 6,
        })
    }

    /// Checks every field that does not depend on the arm; the error names
    /// the key (`plant.<key>`). [`PlantConfig::check_for`] checks the rest.
    pub fn validate(&self) -> Result<(), PlantError> {
        if let Some(s) = self.substeps
            && !(1..=1000).contains(&s)
        {
            return Err(invalid("plant.substeps", s, "an integer from 1 to 1000"));
        }
        if let Some(g) = self.gravity.iter().find(|g| !g.is_finite()) {
            return Err(invalid("plant.gravity", g, "three finite numbers"));
        }
        if let Some(e) = &self.effort_limit {
            e.check("plant.effort_limit")?;
        }
        self.armature.check("plant.armature")?;
        if !(self.mass_scale > 0.0 && self.mass_scale <= 1e3) {
            return Err(invalid(
                "plant.mass_scale",
                self.mass_scale,
                "a factor in (0, 1000]",
            ));
        }
        if let Some((name, v)) = self.lock.iter().find(|(_, v)| !v.is_finite()) {
            return Err(invalid(
                &format!("plant.lock.{name}"),
                v,
                "a finite position",
            ));
        }
        let f = &self.friction;
        f.viscous.check("plant.friction.viscous")?;
        f.coulomb.check("plant.friction.coulomb")?;
        if !(f.smoothing_velocity.is_finite() && f.smoothing_velocity > 0.0) {
            return Err(invalid(
                "plant.friction.smoothing_velocity",
                f.smoothing_velocity,
                "a finite velocity > 0",
            ));
        }
        if let Some(p) = &self.payload {
            p.validate()?;
        }
        self.disturbance.validate()?;
        self.validate_sensor_and_actuation()?;
        self.actuator.validate()?;
        self.contact.validate()?;
        if self.engine != EngineName::Rapier && !self.contact.is_off() {
            return Err(invalid(
                "plant.contact",
                "set",
                "engine = \"rapier\": the articulated engine has no contact solver (add `engine = \"rapier\"` under [plant])",
            ));
        }
        if self.engine == EngineName::Rapier && self.actuator.elastic() {
            return Err(invalid(
                "plant.actuator.stiffness",
                "set",
                "0 with engine = \"rapier\": series-elastic joints are integrated by the articulated engine only",
            ));
        }
        Ok(())
    }

    fn validate_sensor_and_actuation(&self) -> Result<(), PlantError> {
        let s = &self.sensor;
        s.q_noise_std.check("plant.sensor.q_noise_std")?;
        s.qd_noise_std.check("plant.sensor.qd_noise_std")?;
        s.q_resolution.check("plant.sensor.q_resolution")?;
        let a = &self.actuation;
        if a.delay_periods > 10_000 {
            return Err(invalid(
                "plant.actuation.delay_periods",
                a.delay_periods,
                "an integer from 0 to 10000",
            ));
        }
        if !(0.0..=1.0).contains(&a.drop_probability) {
            return Err(invalid(
                "plant.actuation.drop_probability",
                a.drop_probability,
                "a probability from 0 to 1",
            ));
        }
        Ok(())
    }

    /// The effects this configuration turns on (those a state can show
    /// without depending on the run: saturation shows when it happens).
    pub fn configured_effects(&self) -> crate::Effects {
        use crate::Effects as E;
        let d = &self.disturbance;
        let s = &self.sensor;
        let a = &self.actuation;
        let mut bits = 0;
        for (on, bit) in [
            (
                !(self.friction.viscous.is_zero() && self.friction.coulomb.is_zero()),
                E::FRICTION,
            ),
            (self.payload.is_some(), E::PAYLOAD),
            (
                !(d.constant.is_zero()
                    && d.step.is_zero()
                    && d.sin_amplitude.is_zero()
                    && d.noise_std.is_zero()),
                E::DISTURBANCE,
            ),
            (
                !(s.q_noise_std.is_zero() && s.qd_noise_std.is_zero()),
                E::SENSOR_NOISE,
            ),
            (!s.q_resolution.is_zero(), E::QUANTISED),
            (a.delay_periods > 0, E::DELAYED),
            (a.drop_probability > 0.0, E::COMMAND_DROPPED),
            (self.actuator.lags(), E::MOTOR_LAG),
            (self.actuator.has_backlash(), E::BACKLASH),
            (self.actuator.cogs(), E::COGGING),
            (self.actuator.elastic(), E::ELASTIC),
        ] {
            if on {
                bits |= bit;
            }
        }
        E(bits)
    }

    /// The armature the plant simulates per controlled joint: the model's
    /// own (an MJCF joint's `armature`; 0 from a URDF, which has none) plus
    /// the scenario's `[plant] armature` (the motors a URDF leaves out).
    pub fn armature_for(&self, model: &arm_model::ArmModel) -> Result<Vec<f64>, PlantError> {
        let mut armature = self.armature.resolve("plant.armature", model.dof())?;
        for (a, &j) in armature.iter_mut().zip(&model.actuated) {
            *a += model.joints[j].armature;
        }
        Ok(armature)
    }

    /// Checks the per-joint lengths against an arm of `n` joints and the
    /// payload's link against `link_names`.
    pub fn check_for(&self, n: usize, link_names: &[String]) -> Result<(), PlantError> {
        self.validate()?;
        if let Some(e) = &self.effort_limit {
            e.resolve("plant.effort_limit", n)?;
        }
        self.armature.resolve("plant.armature", n)?;
        self.friction.viscous.resolve("plant.friction.viscous", n)?;
        self.friction.coulomb.resolve("plant.friction.coulomb", n)?;
        let d = &self.disturbance;
        d.constant.resolve_signed("plant.disturbance.constant", n)?;
        d.step.resolve_signed("plant.disturbance.step", n)?;
        d.sin_amplitude
            .resolve_signed("plant.disturbance.sin_amplitude", n)?;
        d.noise_std.resolve("plant.disturbance.noise_std", n)?;
        let s = &self.sensor;
        s.q_noise_std.resolve("plant.sensor.q_noise_std", n)?;
        s.qd_noise_std.resolve("plant.sensor.qd_noise_std", n)?;
        s.q_resolution.resolve("plant.sensor.q_resolution", n)?;
        self.actuator.resolve(n)?;
        if let Some(p) = &self.payload
            && !link_names.contains(&p.link)
        {
            return Err(invalid(
                "plant.payload.link",
                format!("\"{}\"", p.link),
                format!("one of the robot's links ({})", link_names.join(", ")),
            ));
        }
        Ok(())
    }
}

impl PayloadConfig {
    fn validate(&self) -> Result<(), PlantError> {
        let p = self;
        if p.link.is_empty() {
            return Err(invalid(
                "plant.payload.link",
                "\"\"",
                "the name of a link of the robot",
            ));
        }
        if !(p.mass.is_finite() && p.mass > 0.0) {
            return Err(invalid("plant.payload.mass", p.mass, "a finite mass > 0"));
        }
        check_finite("plant.payload.offset", &p.offset)?;
        if !(p.attach_at_s.is_finite() && p.attach_at_s >= 0.0) {
            return Err(invalid(
                "plant.payload.attach_at_s",
                p.attach_at_s,
                "a finite time ≥ 0",
            ));
        }
        Ok(())
    }
}

impl DisturbanceConfig {
    fn validate(&self) -> Result<(), PlantError> {
        let d = self;
        d.constant.check_signed("plant.disturbance.constant")?;
        d.step.check_signed("plant.disturbance.step")?;
        d.sin_amplitude
            .check_signed("plant.disturbance.sin_amplitude")?;
        for (key, v) in [
            ("plant.disturbance.step_at_s", d.step_at_s),
            ("plant.disturbance.sin_omega", d.sin_omega),
        ] {
            if !v.is_finite() {
                return Err(invalid(key, v, "a finite number"));
            }
        }
        d.noise_std.check("plant.disturbance.noise_std")?;
        if !(d.noise_bandwidth_hz.is_finite() && d.noise_bandwidth_hz > 0.0) {
            return Err(invalid(
                "plant.disturbance.noise_bandwidth_hz",
                d.noise_bandwidth_hz,
                "a finite frequency > 0",
            ));
        }
        Ok(())
    }
}
