//! A URDF's origins and collision primitives as Rapier's poses and
//! shapes, for the multibody, its colliders and the checks made before a
//! contact run.

use arm_model::{Geometry, Origin};
use rapier3d_f64::glamx::EulerRot;
use rapier3d_f64::prelude::*;

/// A URDF origin (xyz, then roll-pitch-yaw about fixed axes) as a pose.
pub(super) fn pose(o: &Origin) -> Pose {
    Pose::from_parts(
        Vector::new(o.xyz[0], o.xyz[1], o.xyz[2]),
        Rotation::from_euler(EulerRot::ZYX, o.rpy[2], o.rpy[1], o.rpy[0]),
    )
}

/// A URDF primitive as a Rapier shape; cylinders and capsules along z.
pub(super) fn shape(g: &Geometry) -> ColliderBuilder {
    match *g {
        Geometry::Box { size } => {
            ColliderBuilder::cuboid(size[0] / 2.0, size[1] / 2.0, size[2] / 2.0)
        }
        Geometry::Sphere { radius } => ColliderBuilder::ball(radius),
        Geometry::Capsule { radius, length } => ColliderBuilder::capsule_z(length / 2.0, radius),
        Geometry::Cylinder { radius, length } => {
            // Rapier's cylinder lies along y: a quarter turn about x puts it on z.
            let turn = Pose::from_parts(
                Vector::ZERO,
                Rotation::from_axis_angle(Vector::X, std::f64::consts::FRAC_PI_2),
            );
            ColliderBuilder::compound(vec![(turn, SharedShape::cylinder(length / 2.0, radius))])
        }
    }
}
