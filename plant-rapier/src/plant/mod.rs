//! The arm built from an [`ArmModel`], stepped with joint torques, by one of
//! two engines ([`EngineName`]): its equations of motion in joint
//! coordinates (the default), or Rapier's multibody pipeline.

use crate::{EngineError, EngineName, PlantConfig, PlantError};
use arm_model::ArmModel;

mod articulated;
mod build;
mod contact;
mod contact_check;
mod motor;
mod period_cost;
mod rapier;
mod shapes;

use articulated::{Articulated, Drive, Setup, Springs, Stage};
use motor::Motors;
use rapier::RapierArm;

pub use contact::ContactReading;
pub use contact_check::check_contact;
pub use period_cost::{MAX_SUBSTEPS_PER_SECOND, PeriodCost, StiffCause};

/// The engine that integrates the rigid-body dynamics.
enum Engine {
    Articulated(Box<Articulated>),
    Rapier(Box<RapierArm>),
}

/// An arm simulated in double precision.
pub struct Plant {
    engine: Engine,
    names: Vec<String>,
    substeps: u32,
    /// Effort limit per joint (infinite when none or saturation is off).
    effort: Vec<f64>,
    /// The command the motors were given over the last step, after
    /// saturation.
    commanded: Vec<f64>,
    /// The motors' mean torque over the last step.
    applied: Vec<f64>,
    /// Whether the last step clipped any joint's torque.
    saturated: bool,
    /// Torque from outside the motors (the disturbance), held until changed.
    external: Vec<f64>,
    friction: Friction,
    motors: Motors,
}

/// Joint friction the scenario adds: viscous coefficient, Coulomb level
/// and the velocity that smooths it, per joint.
#[derive(Debug, Clone)]
struct Friction {
    viscous: Vec<f64>,
    coulomb: Vec<f64>,
    smoothing_velocity: f64,
}

/// What drives the joints over a step: the motors (through their
/// transmissions) and the external torque, minus the friction at the
/// current velocity.
struct Torques<'a> {
    motors: &'a Motors,
    external: &'a [f64],
    friction: &'a Friction,
}

impl Drive for Torques<'_> {
    fn torque(&self, at: &Stage, out: &mut [f64], dx: &mut [f64]) {
        let (f, n) = (self.friction, out.len());
        for (i, x) in out.iter_mut().enumerate() {
            let (link, motor_accel) = self.motors.drive(i, at.s, at.q[i], at.qd[i], at.x);
            if !dx.is_empty() {
                dx[i] = at.x[n + i];
                dx[n + i] = motor_accel;
            }
            *x = link + self.external[i]
                - friction(at.qd[i], f.viscous[i], f.coulomb[i], f.smoothing_velocity);
        }
    }
}

impl std::fmt::Debug for Plant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Plant")
            .field("joints", &self.names)
            .field("engine", &self.engine_name())
            .field("substeps", &self.substeps)
            .finish_non_exhaustive()
    }
}

impl Plant {
    /// Builds the arm for `model` at q = 0, q̇ = 0.
    pub fn new(model: &ArmModel, config: &PlantConfig) -> Result<Self, PlantError> {
        let n = model.dof();
        config.check_for(n, &model.link_names())?;
        if n == 0 {
            return Err(PlantError::NoActuatedJoints);
        }
        let armature = config.armature_for(model)?;
        build::refuse_massless(model, &armature)?;
        let f = &config.friction;
        let friction = Friction {
            viscous: f.viscous.resolve("plant.friction.viscous", n)?,
            coulomb: f.coulomb.resolve("plant.friction.coulomb", n)?,
            smoothing_velocity: f.smoothing_velocity,
        };
        let motors = Motors::new(config.actuator.resolve(n)?);
        let engine = match config.engine {
            EngineName::Articulated => {
                let spring = |f: fn(&crate::Spring) -> f64| -> Vec<f64> {
                    let joints = motors.joints();
                    joints
                        .iter()
                        .map(|j| j.spring.as_ref().map_or(0.0, f))
                        .collect()
                };
                let (stiffness, damping) = (spring(|s| s.stiffness), spring(|s| s.damping));
                let per_inertia = |f: fn(&crate::Spring) -> f64| {
                    motors
                        .joints()
                        .iter()
                        .filter_map(|j| j.spring.as_ref())
                        .map(|s| f(s) / s.motor_inertia)
                        .fold(0.0, f64::max)
                };
                let slope: Vec<f64> = (0..n)
                    .map(|i| {
                        friction.viscous[i] + friction.coulomb[i] / friction.smoothing_velocity
                    })
                    .collect();
                let setup = Setup {
                    gravity: config.gravity,
                    armature: &armature,
                    urdf_dynamics: config.urdf_dynamics,
                    extra_damping: &slope,
                    springs: Springs {
                        stiffness: &stiffness,
                        damping: &damping,
                        per_motor_inertia: (
                            per_inertia(|s| s.stiffness),
                            per_inertia(|s| s.damping),
                        ),
                        states: motors.extra_states(),
                    },
                };
                Engine::Articulated(Box::new(Articulated::new(model, &setup)?))
            }
            EngineName::Rapier => {
                Engine::Rapier(Box::new(RapierArm::new(model, config, &armature)?))
            }
        };
        Ok(Self {
            engine,
            names: model.joint_names(),
            substeps: config.substeps_or_default(),
            effort: build::effort_limits(model, config)?,
            commanded: vec![0.0; n],
            applied: vec![0.0; n],
            saturated: false,
            external: vec![0.0; n],
            friction,
            motors,
        })
    }

    /// Number of actuated joints.
    pub fn dof(&self) -> usize {
        self.names.len()
    }

    /// Actuated joint names in order (the order of q, q̇ and τ).
    pub fn joint_names(&self) -> &[String] {
        &self.names
    }

    /// Integrator steps per control period.
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// Integrator steps the engine takes in a period of `dt` s: the
    /// scenario's substeps, or more where stiff scenario friction needs
    /// them (the articulated engine; URDF damping never does).
    pub fn substeps_per_period(&self, dt: f64) -> u32 {
        match &self.engine {
            Engine::Articulated(a) => a.substeps_for(dt, self.substeps),
            Engine::Rapier(_) => self.substeps,
        }
    }

    /// The engine that integrates the dynamics.
    pub fn engine_name(&self) -> EngineName {
        match self.engine {
            Engine::Articulated(_) => EngineName::Articulated,
            Engine::Rapier(_) => EngineName::Rapier,
        }
    }

    /// Joint positions and velocities into `q` and `qd` (length `dof()`).
    pub fn state_into(&self, q: &mut [f64], qd: &mut [f64]) {
        match &self.engine {
            Engine::Articulated(a) => {
                let (aq, aqd) = a.state();
                q.copy_from_slice(aq);
                qd.copy_from_slice(aqd);
            }
            Engine::Rapier(r) => r.state_into(q, qd),
        }
    }

    /// Joint positions and velocities as new vectors.
    pub fn state(&self) -> (Vec<f64>, Vec<f64>) {
        let (mut q, mut qd) = (vec![0.0; self.dof()], vec![0.0; self.dof()]);
        self.state_into(&mut q, &mut qd);
        (q, qd)
    }

    /// Puts the arm at `q`, `qd`.
    pub fn set_state(&mut self, q: &[f64], qd: &[f64]) -> Result<(), PlantError> {
        self.check("q", q)?;
        self.check("qd", qd)?;
        match &mut self.engine {
            Engine::Articulated(a) => {
                a.set_state(q, qd);
                self.motors.rest_at(q, qd, a.extra_state_mut());
                Ok(())
            }
            Engine::Rapier(r) => r.set_state(q, qd),
        }
    }

    /// The series-elastic motors' angles and speeds (None without them).
    pub fn motor_state(&self) -> Option<(&[f64], &[f64])> {
        match &self.engine {
            Engine::Articulated(a) if !a.extra_state().is_empty() => {
                Some(a.extra_state().split_at(self.dof()))
            }
            _ => None,
        }
    }

    /// Advances the arm by `dt` seconds with joint torques (forces for
    /// prismatic joints) `tau` held constant (zero-order hold).
    pub fn step(&mut self, tau: &[f64], dt: f64) -> Result<(), PlantError> {
        self.check("tau", tau)?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(PlantError::NotFinite {
                field: "dt".into(),
                value: dt,
            });
        }
        self.saturated = false;
        for ((c, t), e) in self.commanded.iter_mut().zip(tau).zip(&self.effort) {
            *c = t.clamp(-e, *e);
            self.saturated |= *c != *t;
        }
        self.motors.begin(&self.commanded);
        let drive = Torques {
            motors: &self.motors,
            external: &self.external,
            friction: &self.friction,
        };
        match &mut self.engine {
            Engine::Articulated(a) => a.step(&drive, dt, self.substeps)?,
            Engine::Rapier(r) => r.step(&drive, dt, self.substeps),
        }
        self.motors.mean_into(dt, &mut self.applied);
        self.motors.end(dt);
        Ok(())
    }

    /// The joint-space dynamics at the current state, with the plant's
    /// armature and URDF damping: M(q) (row-major, n × n) and the bias
    /// h(q, q̇) = C(q, q̇) q̇ + G(q) + D q̇, so M q̈ + h = τ. Exact where a
    /// step's response to unit torques would mix in the motion within the
    /// step. Only the articulated engine computes them.
    pub fn inertia_and_bias(&mut self) -> Result<(Vec<f64>, Vec<f64>), PlantError> {
        let n = self.dof();
        let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
        match &mut self.engine {
            Engine::Articulated(a) => a.inertia_and_bias(&mut m, &mut h)?,
            Engine::Rapier(_) => {
                return Err(EngineError::NoJointSpaceDynamics.into());
            }
        }
        Ok((m, h))
    }

    /// The friction torque each joint feels at its current velocity
    /// (the torque the friction model adds, so opposite to q̇).
    pub fn friction_torque(&self) -> Vec<f64> {
        let (_, qd) = self.state();
        let f = &self.friction;
        (0..self.dof())
            .map(|i| -friction(qd[i], f.viscous[i], f.coulomb[i], f.smoothing_velocity))
            .collect()
    }

    /// Sets the torque from outside the motors (the disturbance d of eq. 1),
    /// held over the following steps until set again. Saturation does not
    /// touch it: it does not come from the motors.
    pub fn set_external_torque(&mut self, d: &[f64]) -> Result<(), PlantError> {
        self.check("external torque", d)?;
        self.external.copy_from_slice(d);
        Ok(())
    }

    /// The torque from outside the motors, as last set.
    pub fn external_torque(&self) -> &[f64] {
        &self.external
    }

    /// What contact did over the last step: `None` when the scenario has no
    /// `[plant.contact]` (or the engine is the articulated one, which has
    /// none).
    pub fn contact(&self) -> Option<ContactReading> {
        match &self.engine {
            Engine::Articulated(_) => None,
            Engine::Rapier(r) => r.contact(),
        }
    }

    /// Where `[[plant.contact.object]]` `i` is, world frame, m (`None`: no
    /// such object).
    pub fn object_position(&self, i: usize) -> Option<[f64; 3]> {
        match &self.engine {
            Engine::Articulated(_) => None,
            Engine::Rapier(r) => r.object_position(i),
        }
    }

    /// `[[plant.contact.object]]` `i` is grasped by its link (`on`) or let
    /// go (only a plant with contact has objects).
    pub fn hold_object(&mut self, i: usize, on: bool) -> Result<(), PlantError> {
        match &mut self.engine {
            Engine::Articulated(_) => Err(EngineError::NoContactObjects {
                engine: "articulated",
            }
            .into()),
            Engine::Rapier(r) => r.hold(i, on),
        }
    }

    /// Whether the last step clipped any joint's torque at its effort limit.
    pub fn saturated(&self) -> bool {
        self.saturated
    }

    /// Fixes a point mass `mass` to the body of link index `link` at `point`
    /// in that link's frame (a payload picked up). Replaces any earlier one
    /// on that link.
    pub fn attach_point_mass(
        &mut self,
        link: usize,
        point: [f64; 3],
        mass: f64,
    ) -> Result<(), PlantError> {
        match &mut self.engine {
            Engine::Articulated(a) => match a.attach_point_mass(link, point, mass) {
                true => Ok(()),
                false => Err(EngineError::NoLink { link }.into()),
            },
            Engine::Rapier(r) => r.attach_point_mass(link, point, mass),
        }
    }

    /// The motor torque applied over the last step, on average: the command
    /// clipped to the effort limits, through the motors' lag and slew limit
    /// (a series-elastic joint's link feels it through its spring).
    pub fn applied_torque(&self) -> &[f64] {
        &self.applied
    }

    /// Effort limit per joint (infinite where there is none or saturation is off).
    pub fn effort_limits(&self) -> &[f64] {
        &self.effort
    }

    fn check(&self, field: &'static str, v: &[f64]) -> Result<(), PlantError> {
        if v.len() != self.dof() {
            return Err(PlantError::WrongLength {
                field,
                expected: self.dof(),
                got: v.len(),
            });
        }
        match v.iter().position(|x| !x.is_finite()) {
            Some(i) => Err(PlantError::NotFinite {
                field: format!("{field}[{i}] ({})", self.names[i]),
                value: v[i],
            }),
            None => Ok(()),
        }
    }
}

/// The friction torque magnitude model: b q̇ + F_c tanh(q̇ / v_s). The plant
/// subtracts it, so it always opposes the motion.
fn friction(qd: f64, viscous: f64, coulomb: f64, smoothing_velocity: f64) -> f64 {
    viscous * qd + coulomb * (qd / smoothing_velocity).tanh()
}
