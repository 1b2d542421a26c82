//! What the 3D view draws of a contact scenario: its obstacles, fixed in
//! the world, with the arm's figure on `/arm/scene`, and the point where
//! the arm touches one on `/arm/contact` while it does.

use arm_model::{Geometry, Origin, iso};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::ros2::{self, Marker, WORLD_FRAME, parts};

/// Topic of the contact point marker.
pub const CONTACT_MARKER_TOPIC: &str = "/arm/contact";

/// An obstacle as the logger draws it (the launcher fills it from the
/// scenario's `[[plant.contact.obstacle]]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrawnObstacle {
    /// Centre, world frame, m.
    pub xyz: [f64; 3],
    /// Fixed-axis roll, pitch, yaw, rad.
    pub rpy: [f64; 3],
    /// Its shape.
    pub shape: DrawnShape,
}

/// A primitive shape, sized as URDF sizes it (cylinders and capsules along z).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum DrawnShape {
    /// Side lengths, m.
    Box {
        /// [x, y, z], m.
        size: [f64; 3],
    },
    /// A ball.
    Sphere {
        /// m.
        radius: f64,
    },
    /// A cylinder along z.
    Cylinder {
        /// m.
        radius: f64,
        /// m.
        length: f64,
    },
    /// A capsule along z (`length` between the caps' centres).
    Capsule {
        /// m.
        radius: f64,
        /// m.
        length: f64,
    },
}

impl DrawnObstacle {
    /// The obstacle at `origin` shaped `g`.
    pub fn new(origin: &Origin, g: &Geometry) -> Self {
        let shape = match *g {
            Geometry::Box { size } => DrawnShape::Box { size },
            Geometry::Sphere { radius } => DrawnShape::Sphere { radius },
            Geometry::Cylinder { radius, length } => DrawnShape::Cylinder { radius, length },
            Geometry::Capsule { radius, length } => DrawnShape::Capsule { radius, length },
        };
        Self {
            xyz: origin.xyz,
            rpy: origin.rpy,
            shape,
        }
    }

    /// Its marker in the world frame (a capsule drawn as the cylinder that
    /// holds it), numbered `id`.
    pub(crate) fn marker(&self, id: i32) -> Marker {
        let (kind, scale) = match self.shape {
            DrawnShape::Box { size } => (CUBE, size),
            DrawnShape::Sphere { radius } => (SPHERE, [2.0 * radius; 3]),
            DrawnShape::Cylinder { radius, length } => {
                (CYLINDER, [2.0 * radius, 2.0 * radius, length])
            }
            DrawnShape::Capsule { radius, length } => (
                CYLINDER,
                [2.0 * radius, 2.0 * radius, length + 2.0 * radius],
            ),
        };
        let origin = Origin {
            xyz: self.xyz,
            rpy: self.rpy,
        };
        Marker {
            frame: WORLD_FRAME.into(),
            id,
            kind,
            pose: parts(&iso(&origin)),
            scale,
            color: [0.55, 0.55, 0.55, 0.8],
            lifetime_ns: 0,
        }
    }
}

/// The contact point as a red ball in the world frame, 1 cm across per
/// 100 N of mean contact force (from 1 to 10 cm).
pub(crate) fn contact_marker(
    out: &mut Vec<u8>,
    t_ns: u64,
    c: &wire::ContactState,
    lifetime_ns: u64,
) {
    let d = (c.force / 1e4).clamp(0.01, 0.1);
    let pose = Isometry3::from_parts(
        Vector3::new(c.point_x, c.point_y, c.point_z).into(),
        UnitQuaternion::identity(),
    );
    let markers = match c.points {
        0 => Vec::new(),
        _ => vec![Marker {
            frame: WORLD_FRAME.into(),
            id: 0,
            kind: SPHERE,
            pose: parts(&pose),
            scale: [d; 3],
            color: [0.9, 0.1, 0.1, 1.0],
            lifetime_ns,
        }],
    };
    ros2::marker_array(out, t_ns, &markers);
}

/// `visualization_msgs/Marker.CUBE`.
const CUBE: i32 = 1;
/// `visualization_msgs/Marker.SPHERE`.
const SPHERE: i32 = 2;
/// `visualization_msgs/Marker.CYLINDER`.
const CYLINDER: i32 = 3;

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::scene::ArmScene;

    /// The obstacles join the arm's figure in the world frame, each with
    /// its shape's marker and size; the arm's own markers are unchanged.
    #[test]
    fn obstacles_are_drawn_in_the_world_beside_the_arm() {
        let model = arm_model::ArmModel::from_urdf_str(arm_model::TWO_LINK_URDF).unwrap();
        let table = DrawnObstacle::new(
            &Origin {
                xyz: [0.3, 0.0, -0.55],
                rpy: [0.0; 3],
            },
            &Geometry::Box {
                size: [1.0, 0.5, 0.1],
            },
        );
        let ball = DrawnObstacle::new(
            &Origin::default(),
            &Geometry::Capsule {
                radius: 0.1,
                length: 0.4,
            },
        );
        let bare = ArmScene::new(&model).markers();
        let drawn = ArmScene::new(&model)
            .with_obstacles(&[table, ball])
            .markers();
        assert_eq!(drawn[..bare.len()], bare[..]);
        let extra = &drawn[bare.len()..];
        assert_eq!(extra.len(), 2);
        assert_eq!((extra[0].kind, extra[0].scale), (CUBE, [1.0, 0.5, 0.1]));
        assert_eq!(extra[0].pose.0, [0.3, 0.0, -0.55]);
        assert_eq!(extra[0].frame, WORLD_FRAME);
        // A capsule: the cylinder that holds it, caps included.
        assert_eq!(extra[1].kind, CYLINDER);
        assert!((extra[1].scale[2] - 0.6).abs() < 1e-12 && extra[1].scale[0] == 0.2);
        assert_eq!(extra[1].id, 1);
    }
}
