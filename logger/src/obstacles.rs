//! What the 3D view draws of a contact scenario: its obstacles, fixed in
//! the world, with the arm's figure on `/arm/scene`; and on `/arm/contact`
//! the point where the arm touches something while it does, and each free
//! object where the plant says it is.

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

impl DrawnShape {
    /// The shape of a URDF primitive.
    pub fn of(g: &Geometry) -> Self {
        match *g {
            Geometry::Box { size } => Self::Box { size },
            Geometry::Sphere { radius } => Self::Sphere { radius },
            Geometry::Cylinder { radius, length } => Self::Cylinder { radius, length },
            Geometry::Capsule { radius, length } => Self::Capsule { radius, length },
        }
    }

    /// Its marker at `pose` in the world frame (a capsule drawn as the
    /// cylinder that holds it), numbered `id`.
    fn marker(self, id: i32, pose: &Isometry3<f64>, color: [f32; 4], lifetime_ns: u64) -> Marker {
        let (kind, scale) = match self {
            Self::Box { size } => (CUBE, size),
            Self::Sphere { radius } => (SPHERE, [2.0 * radius; 3]),
            Self::Cylinder { radius, length } => (CYLINDER, [2.0 * radius, 2.0 * radius, length]),
            Self::Capsule { radius, length } => (
                CYLINDER,
                [2.0 * radius, 2.0 * radius, length + 2.0 * radius],
            ),
        };
        Marker {
            frame: WORLD_FRAME.into(),
            id,
            kind,
            pose: parts(pose),
            scale,
            color,
            lifetime_ns,
        }
    }
}

impl DrawnObstacle {
    /// The obstacle at `origin` shaped `g`.
    pub fn new(origin: &Origin, g: &Geometry) -> Self {
        Self {
            xyz: origin.xyz,
            rpy: origin.rpy,
            shape: DrawnShape::of(g),
        }
    }

    /// Its marker in the world frame, numbered `id`.
    pub(crate) fn marker(&self, id: i32) -> Marker {
        let origin = Origin {
            xyz: self.xyz,
            rpy: self.rpy,
        };
        self.shape
            .marker(id, &iso(&origin), [0.55, 0.55, 0.55, 0.8], 0)
    }
}

/// The contact point as a red ball in the world frame, 1 cm across per
/// 100 N of mean contact force (from 1 to 10 cm), and each free object
/// (`objects`: their shapes, in order) at the pose `c` gives it, green.
pub(crate) fn contact_marker(
    out: &mut Vec<u8>,
    t_ns: u64,
    c: &wire::ContactState,
    objects: &[DrawnShape],
    lifetime_ns: u64,
) {
    let mut markers = Vec::new();
    if c.points > 0 {
        let d = (c.force / 1e4).clamp(0.01, 0.1);
        let at = Isometry3::from_parts(
            Vector3::new(c.point_x, c.point_y, c.point_z).into(),
            UnitQuaternion::identity(),
        );
        markers.push(DrawnShape::Sphere { radius: d / 2.0 }.marker(
            0,
            &at,
            [0.9, 0.1, 0.1, 1.0],
            lifetime_ns,
        ));
    }
    let poses = c.objects[..(c.count as usize).min(wire::MAX_DOF)].chunks_exact(7);
    for (i, (shape, p)) in objects.iter().zip(poses).enumerate() {
        let Some(at) = object_pose(p) else { continue };
        markers.push(shape.marker(1 + i as i32, &at, [0.2, 0.7, 0.3, 1.0], lifetime_ns));
    }
    ros2::marker_array(out, t_ns, &markers);
}

/// An object's pose from its 7 numbers (None if not finite or not a
/// rotation).
fn object_pose(p: &[f64]) -> Option<Isometry3<f64>> {
    if !p.iter().all(|x| x.is_finite()) {
        return None;
    }
    let q = nalgebra::Quaternion::new(p[6], p[3], p[4], p[5]);
    let r = UnitQuaternion::try_new(q, 1e-9)?;
    Some(Isometry3::from_parts(
        Vector3::new(p[0], p[1], p[2]).into(),
        r,
    ))
}

/// `visualization_msgs/Marker.CUBE`.
const CUBE: i32 = 1;
/// `visualization_msgs/Marker.SPHERE`.
const SPHERE: i32 = 2;
/// `visualization_msgs/Marker.CYLINDER`.
const CYLINDER: i32 = 3;

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
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
