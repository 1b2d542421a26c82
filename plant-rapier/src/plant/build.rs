//! Building the multibody's parts: where each joint lives in it, mimic
//! couplings, per-DoF damping, friction and armature, mass properties.

use rapier3d_f64::prelude::*;

use super::shapes::pose;
use crate::{EngineError, PlantConfig, PlantError};
use arm_model::{ArmModel, JointKind};

/// Where one actuated joint lives inside the Rapier multibody.
#[derive(Debug, Clone)]
pub(super) struct Dof {
    pub(super) link_id: usize,
    pub(super) assembly_id: usize,
    /// Index into the joint's 6-vector of coordinates (LinX = 0, AngX = 3).
    pub(super) coord: usize,
    pub(super) prismatic: bool,
    pub(super) parent: RigidBodyHandle,
    pub(super) child: RigidBodyHandle,
    /// Joint axis in the parent body's frame.
    pub(super) axis_in_parent: Vector,
}

/// A joint that follows a controlled one by `<mimic>`: where it lives and
/// how it is coupled, to keep `set_state` consistent with the coupling.
#[derive(Debug, Clone)]
pub(super) struct Coupled {
    pub(super) link_id: usize,
    pub(super) assembly_id: usize,
    pub(super) coord: usize,
    pub(super) leader: usize,
    pub(super) multiplier: f64,
    pub(super) offset: f64,
}

/// Where controlled joint `ji` lives in the multibody.
pub(super) fn dof_of(
    model: &ArmModel,
    ji: usize,
    handles: &[RigidBodyHandle],
    joints: &MultibodyJointSet,
    multibody: MultibodyJointHandle,
) -> Result<Dof, PlantError> {
    let j = &model.joints[ji];
    let child = handles[j.child];
    let (link_id, assembly_id, frame1) = locate(joints, multibody, child, &j.name)?;
    let prismatic = j.kind == JointKind::Prismatic;
    Ok(Dof {
        link_id,
        assembly_id,
        coord: if prismatic { 0 } else { 3 },
        prismatic,
        parent: handles[j.parent],
        child,
        axis_in_parent: frame1.rotation * Vector::X,
    })
}

/// A joint's link id, assembly id and parent-side frame in the multibody.
fn locate(
    joints: &MultibodyJointSet,
    multibody: MultibodyJointHandle,
    child: RigidBodyHandle,
    name: &str,
) -> Result<(usize, usize, Pose), PlantError> {
    let link = joints
        .rigid_body_link(child)
        .ok_or_else(|| EngineError::JointNotInMultibody {
            joint: name.to_owned(),
        })?;
    let (mb, _) = joints
        .get(multibody)
        .ok_or(EngineError::MultibodyVanished {
            when: "while building",
        })?;
    let l = mb
        .link(link.id)
        .ok_or_else(|| EngineError::NoLinkForJoint {
            joint: name.to_owned(),
        })?;
    Ok((link.id, l.assembly_id(), l.joint().data.local_frame1))
}

/// Couples every `<mimic>` joint to its leader: q = multiplier · q_leader + offset.
pub(super) fn couple_mimics(
    model: &ArmModel,
    dofs: &[Dof],
    handles: &[RigidBodyHandle],
    joints: &mut MultibodyJointSet,
    multibody: MultibodyJointHandle,
) -> Result<Vec<Coupled>, PlantError> {
    let mut coupled = Vec::with_capacity(model.mimic.len());
    for m in &model.mimic {
        let j = &model.joints[m.joint];
        let (link_id, assembly_id, _) = locate(joints, multibody, handles[j.child], &j.name)?;
        let coord = if j.kind == JointKind::Prismatic { 0 } else { 3 };
        let leader = &dofs[m.leader];
        let (mb, _) = joints
            .get_mut(multibody)
            .ok_or(EngineError::MultibodyVanished {
                when: "while building",
            })?;
        mb.add_dof_coupling(MultibodyDofCoupling {
            link1: leader.link_id,
            dof1: 0,
            axis1: leader.coord,
            link2: link_id,
            dof2: 0,
            axis2: coord,
            coeff: m.multiplier,
            offset: m.offset,
        });
        coupled.push(Coupled {
            link_id,
            assembly_id,
            coord,
            leader: m.leader,
            multiplier: m.multiplier,
            offset: m.offset,
        });
    }
    Ok(coupled)
}

/// Refuses a controlled joint whose acceleration is undefined: it moves no
/// mass and has no armature.
pub(super) fn refuse_massless(model: &ArmModel, armature: &[f64]) -> Result<(), PlantError> {
    let massless = model.joints_moving_no_mass();
    for (i, name) in model.joint_names().iter().enumerate() {
        if massless.contains(name) && armature[i] <= 0.0 {
            let link = &model.links[model.joints[model.actuated[i]].child].name;
            return Err(PlantError::BadInertia {
                link: link.clone(),
                reason: format!(
                    "joint '{name}' moves this link, but it and everything it carries have no mass: \
                     lock the joint ([plant.lock]), give it armature ([plant] armature) or give the link an <inertial>"
                ),
            });
        }
    }
    Ok(())
}

/// URDF damping and dry friction on every moving joint (unless the scenario
/// turns them off) and the scenario's armature on the controlled ones.
pub(super) fn joint_dynamics(
    model: &ArmModel,
    config: &PlantConfig,
    armature: &[f64],
    dofs: &[Dof],
    coupled: &[Coupled],
    joints: &mut MultibodyJointSet,
    multibody: MultibodyJointHandle,
) -> Result<(), PlantError> {
    let (mb, _) = joints
        .get_mut(multibody)
        .ok_or(EngineError::MultibodyVanished {
            when: "while building",
        })?;
    let at = dofs
        .iter()
        .map(|d| d.assembly_id)
        .chain(coupled.iter().map(|c| c.assembly_id));
    for (ji, a) in model.moving_joints().zip(at) {
        let j = &model.joints[ji];
        if config.urdf_dynamics {
            mb.damping_mut()[a] = j.damping;
            mb.frictions_mut()[a] = j.friction;
        }
    }
    for (d, arm) in dofs.iter().zip(armature) {
        mb.armature_mut()[d.assembly_id] = *arm;
    }
    Ok(())
}

/// A link's mass properties for Rapier. The principal axes are found here
/// in f64 (nalgebra's symmetric eigensolver): Rapier's own decomposition
/// loses the small products of inertia of light links (grams, 1e-5 kg m²),
/// which showed as a 4 % error in the SO-ARM's wrist coupling.
pub(super) fn mass_properties(link: &crate::LinkInfo) -> MassProperties {
    let [ixx, ixy, ixz, iyy, iyz, izz] = link.inertia;
    let tensor = nalgebra::Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
    // URDF gives the tensor in the inertial frame; Rapier wants it in the link frame.
    let frame = arm_model::iso(&link.inertial_origin);
    let r = frame.rotation.to_rotation_matrix();
    let in_link = r.matrix() * tensor * r.matrix().transpose();
    let eigen = in_link.symmetric_eigen();
    let mut axes = eigen.eigenvectors;
    let mut moments = eigen.eigenvalues;
    if axes.determinant() < 0.0 {
        axes.swap_columns(1, 2);
        moments.swap_rows(1, 2);
    }
    let q = nalgebra::UnitQuaternion::from_matrix(&axes);
    let c = frame.translation.vector;
    MassProperties::with_principal_inertia_frame(
        Vector::new(c.x, c.y, c.z),
        link.mass,
        Vector::new(
            moments[0].max(0.0),
            moments[1].max(0.0),
            moments[2].max(0.0),
        ),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

/// Every link as a rigid body at its q = 0 pose (the root fixed), with its
/// own mass properties; the handles and those properties, in link order.
pub(super) fn insert_bodies(
    world: &mut PhysicsWorld,
    model: &ArmModel,
) -> (Vec<RigidBodyHandle>, Vec<MassProperties>) {
    // World pose of every link at q = 0, parents first.
    let mut link_pose = vec![Pose::IDENTITY; model.links.len()];
    for &ji in &model.topological {
        let j = &model.joints[ji];
        link_pose[j.child] = link_pose[j.parent] * pose(&j.origin);
    }
    let mut handles = Vec::with_capacity(model.links.len());
    let mut link_mprops = Vec::with_capacity(model.links.len());
    for (i, link) in model.links.iter().enumerate() {
        let builder = if i == model.root {
            RigidBodyBuilder::fixed()
        } else {
            RigidBodyBuilder::dynamic()
        };
        let mprops = mass_properties(link);
        link_mprops.push(mprops);
        let body = builder
            .pose(link_pose[i])
            .additional_mass_properties(mprops)
            .can_sleep(false)
            .build();
        handles.push(world.bodies.insert(body));
    }
    (handles, link_mprops)
}

/// Every joint into one multibody; its handle.
pub(super) fn insert_joints(
    world: &mut PhysicsWorld,
    model: &ArmModel,
    handles: &[RigidBodyHandle],
) -> Result<MultibodyJointHandle, PlantError> {
    let mut multibody = None;
    for &ji in &model.topological {
        let j = &model.joints[ji];
        let axis = Vector::new(j.axis[0], j.axis[1], j.axis[2]);
        let locked = match j.kind {
            JointKind::Revolute | JointKind::Continuous => JointAxesMask::LOCKED_REVOLUTE_AXES,
            JointKind::Prismatic => JointAxesMask::LOCKED_PRISMATIC_AXES,
            JointKind::Fixed => JointAxesMask::LOCKED_FIXED_AXES,
        };
        // One frame built from the axis, on both sides, so that the joint's
        // local X is the URDF axis and q = 0 is the URDF zero pose.
        let basis = if j.kind == JointKind::Fixed {
            Pose::IDENTITY
        } else {
            Pose::from_rotation(GenericJoint::complete_ang_frame(axis))
        };
        let mut builder = GenericJointBuilder::new(locked)
            .local_frame1(pose(&j.origin) * basis)
            .local_frame2(basis)
            .contacts_enabled(false);
        if let Some((lo, hi)) = j.limits {
            let axis_id = if j.kind == JointKind::Prismatic {
                JointAxis::LinX
            } else {
                JointAxis::AngX
            };
            builder = builder.limits(axis_id, [lo, hi]);
        }
        let handle = world
            .multibody_joints
            .insert(handles[j.parent], handles[j.child], builder.build(), true)
            .ok_or_else(|| EngineError::JointRefused {
                joint: j.name.clone(),
            })?;
        multibody.get_or_insert(handle);
    }
    multibody.ok_or(PlantError::NoActuatedJoints)
}

/// Settles the new multibody: drops the free root, no self-contacts, and
/// none of Rapier's default per-DoF damping, friction or armature.
pub(super) fn settle(
    bodies: &mut RigidBodySet,
    joints: &mut MultibodyJointSet,
    multibody: MultibodyJointHandle,
) -> Result<(), PlantError> {
    let (mb, _) = joints
        .get_mut(multibody)
        .ok_or(EngineError::MultibodyVanished {
            when: "after insertion",
        })?;
    // The root is fixed: this drops the free root DOFs Rapier counts at first.
    mb.forward_kinematics(bodies, true);
    mb.update_rigid_bodies(bodies, true);
    mb.set_self_contacts_enabled(false);
    // Rapier gives every DOF a default joint damping of 0.1: the arm has none.
    mb.damping_mut().fill(0.0);
    mb.frictions_mut().fill(0.0);
    mb.armature_mut().fill(0.0);
    Ok(())
}

/// Effort limit per joint: the scenario's or the URDF's; infinite where
/// there is none or saturation is off.
pub(super) fn effort_limits(
    model: &ArmModel,
    config: &PlantConfig,
) -> Result<Vec<f64>, PlantError> {
    let n = model.dof();
    let scenario_effort = match &config.effort_limit {
        Some(e) => Some(e.resolve("plant.effort_limit", n)?),
        None => None,
    };
    Ok(model
        .actuated
        .iter()
        .enumerate()
        .map(|(i, &ji)| {
            let limit = match &scenario_effort {
                Some(e) => Some(e[i]),
                None => model.joints[ji].effort,
            };
            match limit {
                Some(e) if config.saturate => e,
                _ => f64::INFINITY,
            }
        })
        .collect())
}
