//! The arm as a Rapier multibody, stepped through Rapier's whole pipeline
//! (`plant.engine = "rapier"`): the reference the articulated engine is
//! checked against, and the engine to reach for when Rapier's own joint
//! constraints are what is being studied.

use rapier3d_f64::prelude::*;

use super::articulated::{Drive, Stage};
use super::build::{
    Coupled, Dof, couple_mimics, dof_of, insert_bodies, insert_joints, joint_dynamics, settle,
};
use super::contact::{self, ContactReading, Contacts};
use crate::{EngineError, PlantConfig, PlantError};
use arm_model::ArmModel;

/// An arm simulated by Rapier in double precision.
pub(crate) struct RapierArm {
    world: PhysicsWorld,
    multibody: MultibodyJointHandle,
    dofs: Vec<Dof>,
    coupled: Vec<Coupled>,
    bodies: Vec<RigidBodyHandle>,
    /// Each link's own mass properties, before any payload.
    link_mprops: Vec<MassProperties>,
    /// Scratch: joint velocities and the torque Rapier is given per substep.
    q: Vec<f64>,
    qd: Vec<f64>,
    total: Vec<f64>,
    /// The colliders' bookkeeping when `[plant.contact]` is on.
    contacts: Option<Contacts>,
    /// What contact did over the last period.
    contact: Option<ContactReading>,
}

impl RapierArm {
    /// Builds the multibody for `model` at q = 0, q̇ = 0.
    pub(crate) fn new(
        model: &ArmModel,
        config: &PlantConfig,
        armature: &[f64],
    ) -> Result<Self, PlantError> {
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
            return Err(EngineError::DofMismatch {
                multibody: ndofs,
                model: dofs.len() + coupled.len(),
            }
            .into());
        }
        let parts = (&dofs[..], &coupled[..]);
        joint_dynamics(
            model,
            config,
            armature,
            parts.0,
            parts.1,
            multibody_joints,
            multibody,
        )?;
        let contacts = match config.contact.is_off() {
            true => None,
            false => Some(contact::insert(
                &mut world,
                model,
                &handles,
                &config.contact,
            )?),
        };
        if config.contact.self_contact
            && let Some((mb, _)) = world.multibody_joints.get_mut(multibody)
        {
            // Links that are not neighbours meet (Rapier never lets
            // neighbours collide).
            mb.set_self_contacts_enabled(true);
        }
        let n = dofs.len();
        // Before the first period: no contact yet, the objects where they start.
        let mut contacts = contacts;
        let contact = contacts.as_mut().map(|c| c.end(1.0, &world.colliders));
        Ok(Self {
            world,
            multibody,
            dofs,
            coupled,
            bodies: handles,
            link_mprops,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            total: vec![0.0; n],
            contact,
            contacts,
        })
    }

    fn mb(&self) -> &Multibody {
        // The handle was checked at construction and joints are never removed.
        match self.world.multibody_joints.get(self.multibody) {
            Some((mb, _)) => mb,
            None => unreachable!("multibody handle checked at construction"),
        }
    }

    /// Joint positions and velocities into `q` and `qd`.
    pub(crate) fn state_into(&self, q: &mut [f64], qd: &mut [f64]) {
        let mb = self.mb();
        let v = mb.generalized_velocity();
        for (i, d) in self.dofs.iter().enumerate() {
            q[i] = mb
                .link(d.link_id)
                .map_or(f64::NAN, |l| l.joint().coords()[d.coord]);
            qd[i] = v[d.assembly_id];
        }
    }

    /// Puts the arm at `q`, `qd` (both checked by the caller).
    pub(crate) fn set_state(&mut self, q: &[f64], qd: &[f64]) -> Result<(), PlantError> {
        let PhysicsWorld {
            bodies,
            multibody_joints,
            ..
        } = &mut self.world;
        let Some((mb, _)) = multibody_joints.get_mut(self.multibody) else {
            return Err(EngineError::MultibodyVanished {
                when: "while stepping",
            }
            .into());
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

    /// Advances by `dt` in `substeps` Rapier steps, the torque re-evaluated
    /// (friction follows the velocity, the motors their lag) and re-applied
    /// about the current axes before each.
    pub(crate) fn step(&mut self, drive: &dyn Drive, dt: f64, substeps: u32) {
        let h = dt / f64::from(substeps);
        self.world.integration_parameters.dt = h;
        if let Some(c) = &mut self.contacts {
            c.begin();
        }
        for k in 0..substeps {
            let (mut q, mut qd) = (std::mem::take(&mut self.q), std::mem::take(&mut self.qd));
            self.state_into(&mut q, &mut qd);
            let mut total = std::mem::take(&mut self.total);
            let at = Stage {
                s: f64::from(k) * h,
                q: &q,
                qd: &qd,
                x: &[],
            };
            drive.torque(&at, &mut total, &mut []);
            self.apply_torques(&total);
            (self.q, self.qd, self.total) = (q, qd, total);
            self.world.step();
            if let Some(c) = &mut self.contacts {
                c.after_substep(&self.world.narrow_phase, &self.world.colliders);
            }
        }
        self.contact = self
            .contacts
            .as_mut()
            .map(|c| c.end(dt, &self.world.colliders));
    }

    /// The link named in `[[plant.contact.object]]` `i` grasps it (`on`) or
    /// lets it go.
    pub(crate) fn hold(&mut self, i: usize, on: bool) -> Result<(), PlantError> {
        let Some(c) = &self.contacts else {
            return Err(EngineError::NoContactObjects { engine: "Rapier" }.into());
        };
        match on {
            true => c.grasp(i, &mut self.world),
            false => c.release(i, &mut self.world),
        }
    }

    /// Where contact object `i` is, world frame.
    pub(crate) fn object_position(&self, i: usize) -> Option<[f64; 3]> {
        let p = self
            .contacts
            .as_ref()?
            .object_position(i, &self.world.colliders)?;
        Some([p.x, p.y, p.z])
    }

    /// What contact did over the last period (`None` without contact).
    pub(crate) fn contact(&self) -> Option<ContactReading> {
        self.contact
    }

    /// Fixes a point mass to link `link` at `point` in its frame, replacing
    /// any earlier one there.
    pub(crate) fn attach_point_mass(
        &mut self,
        link: usize,
        point: [f64; 3],
        mass: f64,
    ) -> Result<(), PlantError> {
        let (Some(handle), Some(base)) = (self.bodies.get(link), self.link_mprops.get(link)) else {
            return Err(EngineError::NoLink { link }.into());
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
            .ok_or(EngineError::LinkWithoutBody { link })?;
        body.set_additional_mass_properties(total, true);
        Ok(())
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
}
