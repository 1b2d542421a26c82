//! A link's `<collision>` primitives, read for the contact engine: boxes,
//! cylinders, spheres and capsules as the URDF gives them; meshes are named
//! (the plant says it skipped them) since no mesh file is ever opened here.

use super::Origin;

/// One primitive collision shape of a link, in the link's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionShape {
    /// Pose of the shape in the link frame.
    pub origin: Origin,
    /// The shape itself.
    pub geometry: Geometry,
}

/// A URDF collision primitive. Cylinders and capsules lie along their
/// frame's z axis, as URDF defines them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Geometry {
    /// Full side lengths, m.
    Box {
        /// [x, y, z] side lengths, m.
        size: [f64; 3],
    },
    /// A cylinder along z.
    Cylinder {
        /// Radius, m.
        radius: f64,
        /// Length along z, m.
        length: f64,
    },
    /// A sphere.
    Sphere {
        /// Radius, m.
        radius: f64,
    },
    /// A capsule along z: `length` between the centres of its end caps.
    Capsule {
        /// Radius, m.
        radius: f64,
        /// Length of the cylindrical part, m.
        length: f64,
    },
}

/// A link's collision elements, sorted: the primitives; the meshes (not
/// contact shapes, named by file); and the primitives that cannot be
/// shapes, each with why (a size or origin that is not a finite number up
/// to 1000 m). Never an error here: collisions matter only to a contact
/// scenario, which refuses the bad ones and notes the meshes; every other
/// run ignores them.
pub(super) fn collisions(
    l: &urdf_rs::Link,
    origin: impl Fn(&urdf_rs::Pose) -> Option<Origin>,
) -> Collisions {
    let mut out = Collisions::default();
    for (i, c) in l.collision.iter().enumerate() {
        let what = format!("link '{}' collision {}", l.name, i + 1);
        if let urdf_rs::Geometry::Mesh { filename, .. } = &c.geometry {
            out.meshes.push(format!("{what}: mesh '{filename}'"));
            continue;
        }
        let at =
            origin(&c.origin).filter(|o| o.xyz.iter().chain(&o.rpy).all(|v| v.abs() <= MAX_SIZE));
        match (geometry(&c.geometry), at) {
            (Ok(geometry), Some(origin)) => out.shapes.push(CollisionShape { origin, geometry }),
            (Err(why), _) => out.bad.push(format!("{what}: {why}")),
            (Ok(_), None) => out.bad.push(format!(
                "{what}: its <origin> is not finite numbers up to {MAX_SIZE}"
            )),
        }
    }
    out
}

/// A link's collision elements, sorted (see [`collisions`]).
#[derive(Debug, Default)]
pub(super) struct Collisions {
    pub(super) shapes: Vec<CollisionShape>,
    pub(super) meshes: Vec<String>,
    pub(super) bad: Vec<String>,
}

/// The largest size or offset of a collision primitive, m.
const MAX_SIZE: f64 = 1e3;

fn geometry(g: &urdf_rs::Geometry) -> Result<Geometry, String> {
    let size = |what: &str, v: f64, zero_ok: bool| {
        if v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0)) && v <= MAX_SIZE {
            Ok(v)
        } else {
            Err(format!("<{what}> {v} is not a size in (0, {MAX_SIZE}] m"))
        }
    };
    Ok(match g {
        urdf_rs::Geometry::Mesh { filename, .. } => {
            return Err(format!("mesh '{filename}'"));
        }
        urdf_rs::Geometry::Box { size: s } => Geometry::Box {
            size: [
                size("box size x", s.0[0], false)?,
                size("box size y", s.0[1], false)?,
                size("box size z", s.0[2], false)?,
            ],
        },
        urdf_rs::Geometry::Cylinder { radius, length } => Geometry::Cylinder {
            radius: size("cylinder radius", *radius, false)?,
            length: size("cylinder length", *length, false)?,
        },
        urdf_rs::Geometry::Sphere { radius } => Geometry::Sphere {
            radius: size("sphere radius", *radius, false)?,
        },
        urdf_rs::Geometry::Capsule { radius, length } => Geometry::Capsule {
            radius: size("capsule radius", *radius, false)?,
            length: size("capsule length", *length, true)?,
        },
    })
}
