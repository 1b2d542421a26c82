//! The Rapier multibody built from an [`ArmModel`], stepped with joint torques.

use rapier3d_f64::glamx::EulerRot;
use rapier3d_f64::prelude::*;

use crate::{PlantConfig, PlantError};
use arm_model::{ArmModel, Origin};

mod build;

use build::{
    couple_mimics, dof_of, effort_limits, insert_bodies, insert_joints, joint_dynamics, settle,
};

/// Where one actuated joint lives inside the Rapier multibody.
#[derive(Debug, Clone)]
struct Dof {
    link_id: usize,
    assembly_id: usize,
    /// Index into the joint's 6-vector of coordinates (LinX = 0, AngX = 3).
    coord: usize,
    prismatic: bool,
    parent: RigidBodyHandle,
    child: RigidBodyHandle,
    /// Joint axis in the parent body's frame.
    axis_in_parent: Vector,
}

/// A joint that follows a controlled one by `<mimic>`: where it lives and
/// how it is coupled, to keep `set_state` consistent with the coupling.
#[derive(Debug, Clone)]
struct Coupled {
    link_id: usize,
    assembly_id: usize,
    coord: usize,
    leader: usize,
    multiplier: f64,
    offset: f64,
}

/// An arm simulated by Rapier in double precision.
pub struct Plant {
    world: PhysicsWorld,
    multibody: MultibodyJointHandle,
    dofs: Vec<Dof>,
    coupled: Vec<Coupled>,
    names: Vec<String>,
    substeps: u32,
    bodies: Vec<RigidBodyHandle>,
    /// Effort limit per joint (infinite when none or saturation is off).
    effort: Vec<f64>,
    /// The torque applied over the last step, after saturation.
    applied: Vec<f64>,
    /// Whether the last step clipped any joint's torque.
    saturated: bool,
    /// Torque from outside the motors (the disturbance), held until changed.
    external: Vec<f64>,
    /// Viscous coefficient, Coulomb level, smoothing velocity.
    viscous: Vec<f64>,
    coulomb: Vec<f64>,
    smoothing_velocity: f64,
    /// Each link's own mass properties, before any payload.
    link_mprops: Vec<MassProperties>,
    /// What Rapier is given per substep: applied + external − friction.
    total: Vec<f64>,
}

impl std::fmt::Debug for Plant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Plant")
            .field("joints", &self.names)
            .field("substeps", &self.substeps)
            .finish_non_exhaustive()
    }
}

fn pose(o: &Origin) -> Pose {
    Pose::from_parts(
        Vector::new(o.xyz[0], o.xyz[1], o.xyz[2]),
        Rotation::from_euler(EulerRot::ZYX, o.rpy[2], o.rpy[1], o.rpy[0]),
    )
}

impl Plant {
    /// Builds the multibody for `model` at q = 0, q̇ = 0.
    pub fn new(model: &ArmModel, config: &PlantConfig) -> Result<Self, PlantError> {
        let n = model.dof();
        config.check_for(n, &model.link_names())?;
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(config.gravity[0], config.gravity[1], config.gravity[2]);
        // One solver pass per call; accuracy comes from stepping `substeps`
        // times per period with the torque re-applied about the current axes.
        world.integration_parameters.num_solver_iterations = 1;

        let (handles, link_mprops) = insert_bodies(&mut world, model);
        let multibody = insert_joints(&mut world, model, &handles)?;
        let PhysicsWorld {
            bodies,
            multibody_joints,
            ..
        } = &mut world;
        settle(bodies, multibody_joints, multibody)?;
        let dofs = model
            .actuated
            .iter()
            .map(|&ji| dof_of(model, ji, &handles, multibody_joints, multibody))
            .collect::<Result<Vec<_>, _>>()?;
        let coupled = couple_mimics(model, &dofs, &handles, multibody_joints, multibody)?;
        let ndofs = multibody_joints
            .get(multibody)
            .map(|(mb, _)| mb.ndofs())
            .unwrap_or(0);
        if ndofs != dofs.len() + coupled.len() {
            return Err(PlantError::Engine(format!(
                "the multibody has {ndofs} degrees of freedom but the URDF {} moving joints",
                dofs.len() + coupled.len()
            )));
        }
        joint_dynamics(model, config, &dofs, &coupled, multibody_joints, multibody)?;
        let effort = effort_limits(model, config)?;
        let f = &config.friction;
        Ok(Self {
            world,
            multibody,
            names: model.joint_names(),
            applied: vec![0.0; n],
            saturated: false,
            external: vec![0.0; n],
            viscous: f.viscous.resolve("plant.friction.viscous", n)?,
            coulomb: f.coulomb.resolve("plant.friction.coulomb", n)?,
            smoothing_velocity: f.smoothing_velocity,
            link_mprops,
            total: vec![0.0; n],
            dofs,
            coupled,
            substeps: config.substeps,
            bodies: handles,
            effort,
        })
    }

    /// Number of actuated joints.
    pub fn dof(&self) -> usize {
        self.dofs.len()
    }

    /// Actuated joint names in order (the order of q, q̇ and τ).
    pub fn joint_names(&self) -> &[String] {
        &self.names
    }

    /// Substeps per control period.
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    fn mb(&self) -> &Multibody {
        // The handle was checked at construction and joints are never removed.
        match self.world.multibody_joints.get(self.multibody) {
            Some((mb, _)) => mb,
            None => unreachable!("multibody handle checked at construction"),
        }
    }

    /// Joint positions and velocities into `q` and `qd` (length `dof()`).
    pub fn state_into(&self, q: &mut [f64], qd: &mut [f64]) {
        let mb = self.mb();
        let v = mb.generalized_velocity();
        for (i, d) in self.dofs.iter().enumerate() {
            q[i] = mb
                .link(d.link_id)
                .map_or(f64::NAN, |l| l.joint().coords()[d.coord]);
            qd[i] = v[d.assembly_id];
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
        let PhysicsWorld {
            bodies,
            multibody_joints,
            ..
        } = &mut self.world;
        let Some((mb, _)) = multibody_joints.get_mut(self.multibody) else {
            return Err(PlantError::Engine("multibody vanished".into()));
        };
        let targets = self
            .dofs
            .iter()
            .enumerate()
            .map(|(i, d)| (d.link_id, d.coord, q[i]))
            .chain(
                self.coupled
                    .iter()
                    .map(|c| (c.link_id, c.coord, c.multiplier * q[c.leader] + c.offset)),
            );
        for (link_id, coord, target) in targets {
            if let Some(link) = mb.link_mut(link_id) {
                let now = link.joint().coords()[coord];
                link.joint.apply_displacement(&[target - now]);
            }
        }
        mb.forward_kinematics(bodies, false);
        mb.update_rigid_bodies(bodies, true);
        let mut v = mb.generalized_velocity_mut();
        for (i, d) in self.dofs.iter().enumerate() {
            v[d.assembly_id] = qd[i];
        }
        for c in &self.coupled {
            v[c.assembly_id] = c.multiplier * qd[c.leader];
        }
        Ok(())
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
        for ((a, t), e) in self.applied.iter_mut().zip(tau).zip(&self.effort) {
            *a = t.clamp(-e, *e);
            self.saturated |= *a != *t;
        }
        self.world.integration_parameters.dt = dt / f64::from(self.substeps);
        let has_friction = self.has_friction();
        for _ in 0..self.substeps {
            let mut total = std::mem::take(&mut self.total);
            for ((x, a), d) in total.iter_mut().zip(&self.applied).zip(&self.external) {
                *x = a + d;
            }
            if has_friction {
                // Friction follows the velocity within the period.
                let v = self.mb().generalized_velocity();
                for (i, dof) in self.dofs.iter().enumerate() {
                    total[i] -= friction(
                        v[dof.assembly_id],
                        self.viscous[i],
                        self.coulomb[i],
                        self.smoothing_velocity,
                    );
                }
            }
            self.apply_torques(&total);
            self.total = total;
            self.world.step();
        }
        Ok(())
    }

    /// Whether any joint has friction.
    pub fn has_friction(&self) -> bool {
        self.viscous.iter().chain(&self.coulomb).any(|x| *x != 0.0)
    }

    /// The friction torque each joint feels at its current velocity
    /// (the torque the friction model adds, so opposite to q̇).
    pub fn friction_torque(&self) -> Vec<f64> {
        let (_, qd) = self.state();
        (0..self.dof())
            .map(|i| {
                -friction(
                    qd[i],
                    self.viscous[i],
                    self.coulomb[i],
                    self.smoothing_velocity,
                )
            })
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
        let (Some(handle), Some(base)) = (self.bodies.get(link), self.link_mprops.get(link)) else {
            return Err(PlantError::Engine(format!("no link with index {link}")));
        };
        let payload = MassProperties::new(
            Vector::new(point[0], point[1], point[2]),
            mass,
            Vector::ZERO,
        );
        let total = *base + payload;
        let body = self
            .world
            .bodies
            .get_mut(*handle)
            .ok_or_else(|| PlantError::Engine(format!("link {link} has no body")))?;
        body.set_additional_mass_properties(total, true);
        Ok(())
    }

    /// The torque applied over the last step: the command clipped to the
    /// effort limits.
    pub fn applied_torque(&self) -> &[f64] {
        &self.applied
    }

    /// Effort limit per joint (infinite where there is none or saturation is off).
    pub fn effort_limits(&self) -> &[f64] {
        &self.effort
    }

    /// Rapier has no generalized-force input for multibody joints: a joint
    /// torque is an equal and opposite torque about the joint's current
    /// world axis on child and parent (a force pair at one point for a
    /// prismatic joint). User forces persist across steps, so reset first.
    fn apply_torques(&mut self, tau: &[f64]) {
        let bodies = &mut self.world.bodies;
        for h in &self.bodies {
            if let Some(b) = bodies.get_mut(*h) {
                b.reset_forces(false);
                b.reset_torques(false);
            }
        }
        for (d, &t) in self.dofs.iter().zip(tau) {
            let Some(parent) = bodies.get(d.parent) else {
                continue;
            };
            let axis = parent.position().rotation * d.axis_in_parent;
            if d.prismatic {
                let Some(child) = bodies.get_mut(d.child) else {
                    continue;
                };
                let point = child.center_of_mass();
                child.add_force_at_point(axis * t, point, true);
                if let Some(p) = bodies.get_mut(d.parent) {
                    p.add_force_at_point(-axis * t, point, true);
                }
            } else {
                if let Some(child) = bodies.get_mut(d.child) {
                    child.add_torque(axis * t, true);
                }
                if let Some(p) = bodies.get_mut(d.parent) {
                    p.add_torque(-axis * t, true);
                }
            }
        }
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
