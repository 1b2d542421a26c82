//! Building the multibody's parts: where each joint lives in it, mimic
//! couplings, per-DoF damping, friction and armature, mass properties.

use rapier3d_f64::prelude::*;

use super::{Coupled, Dof};
use crate::model::{ArmModel, JointKind};
use crate::{PlantConfig, PlantError};

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
        .ok_or_else(|| PlantError::Engine(format!("joint '{name}' is not in the multibody")))?;
    let (mb, _) = joints
        .get(multibody)
        .ok_or_else(|| PlantError::Engine("multibody vanished".into()))?;
    let l = mb
        .link(link.id)
        .ok_or_else(|| PlantError::Engine(format!("no link for joint '{name}'")))?;
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
            .ok_or_else(|| PlantError::Engine("multibody vanished".into()))?;
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

/// URDF damping and dry friction on every moving joint (unless the scenario
/// turns them off) and the scenario's armature on the controlled ones.
pub(super) fn joint_dynamics(
    model: &ArmModel,
    config: &PlantConfig,
    dofs: &[Dof],
    coupled: &[Coupled],
    joints: &mut MultibodyJointSet,
    multibody: MultibodyJointHandle,
) -> Result<(), PlantError> {
    let armature = config.armature.resolve("plant.armature", dofs.len())?;
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
    let (mb, _) = joints
        .get_mut(multibody)
        .ok_or_else(|| PlantError::Engine("multibody vanished".into()))?;
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
    for (d, arm) in dofs.iter().zip(&armature) {
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
    let frame = crate::model::iso(&link.inertial_origin);
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
