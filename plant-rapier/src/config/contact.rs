//! `[plant.contact]`: the arm's links touch obstacles in its workspace
//! through Rapier's contact solver. Off unless an obstacle (or contact
//! between the arm's own links) is written; the articulated engine refuses
//! it by name, since it integrates joint coordinates without a contact
//! solver.

use arm_model::{Geometry, Origin};
use serde::{Deserialize, Serialize};

use super::invalid;
use crate::PlantError;

/// Contact between the arm's `<collision>` primitives and the obstacles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ContactConfig {
    /// Coefficient of restitution of every contact, from 0 (plastic) to 1
    /// (elastic) (default: 0).
    pub restitution: f64,
    /// Coulomb friction coefficient of every contact (default: 0.5).
    pub friction: f64,
    /// Whether links that are not neighbours in the tree collide with each
    /// other (default: false).
    pub self_contact: bool,
    /// Fixed bodies in the workspace.
    pub obstacle: Vec<Obstacle>,
}

impl Default for ContactConfig {
    fn default() -> Self {
        Self {
            restitution: 0.0,
            friction: 0.5,
            self_contact: false,
            obstacle: Vec::new(),
        }
    }
}

/// A fixed obstacle: a primitive shape at a pose in the world frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// A name for errors and the 3D view (default: "obstacle N").
    #[serde(default)]
    pub name: String,
    /// `box`, `sphere`, `cylinder` or `capsule` (cylinders and capsules lie
    /// along the obstacle's z axis, as in URDF).
    pub shape: ShapeName,
    /// Box: the three side lengths; sphere: the radius; cylinder and
    /// capsule: the radius and the length, m.
    pub size: Vec<f64>,
    /// Position of the shape's centre in the world frame, m.
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Fixed-axis roll, pitch, yaw, rad.
    #[serde(default)]
    pub rpy: [f64; 3],
}

/// The primitive shapes an obstacle can have.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShapeName {
    /// A box of three side lengths.
    Box,
    /// A ball.
    Sphere,
    /// A cylinder along z.
    Cylinder,
    /// A capsule along z (length between the caps' centres).
    Capsule,
}

impl ContactConfig {
    /// Whether contact is simulated at all (the key is then not written, so
    /// that scenarios' identities keep).
    pub fn is_off(&self) -> bool {
        self.obstacle.is_empty() && !self.self_contact
    }

    /// Checks every entry; errors name the key.
    pub fn validate(&self) -> Result<(), PlantError> {
        if !(0.0..=1.0).contains(&self.restitution) {
            return Err(invalid(
                "plant.contact.restitution",
                self.restitution,
                "a number from 0 to 1",
            ));
        }
        if !(self.friction.is_finite() && (0.0..=100.0).contains(&self.friction)) {
            return Err(invalid(
                "plant.contact.friction",
                self.friction,
                "a coefficient from 0 to 100",
            ));
        }
        if self.obstacle.len() > MAX_OBSTACLES {
            return Err(invalid(
                "plant.contact.obstacle",
                format!("{} obstacles", self.obstacle.len()),
                format!("at most {MAX_OBSTACLES}"),
            ));
        }
        for (i, o) in self.obstacle.iter().enumerate() {
            o.geometry(i)?;
            let key = |k: &str| format!("plant.contact.obstacle[{i}].{k}");
            if let Some(v) = o.xyz.iter().chain(&o.rpy).find(|v| !v.is_finite()) {
                return Err(invalid(&key("xyz/rpy"), v, "finite numbers"));
            }
        }
        Ok(())
    }
}

/// More obstacles than a workspace needs is a mistake, not a scene.
const MAX_OBSTACLES: usize = 1000;

impl Obstacle {
    /// The obstacle's shape, checked; `i` is its index for errors.
    pub fn geometry(&self, i: usize) -> Result<Geometry, PlantError> {
        let key = format!("plant.contact.obstacle[{i}].size");
        let want = match self.shape {
            ShapeName::Box => "three side lengths > 0, m",
            ShapeName::Sphere => "one radius > 0, m",
            ShapeName::Cylinder | ShapeName::Capsule => "a radius and a length > 0, m",
        };
        let s = &self.size;
        let bad = || invalid(&key, format!("{s:?}"), want);
        if s.iter().any(|v| !(v.is_finite() && *v > 0.0 && *v <= 1e3)) {
            return Err(bad());
        }
        Ok(match (self.shape, s.as_slice()) {
            (ShapeName::Box, &[x, y, z]) => Geometry::Box { size: [x, y, z] },
            (ShapeName::Sphere, &[radius]) => Geometry::Sphere { radius },
            (ShapeName::Cylinder, &[radius, length]) => Geometry::Cylinder { radius, length },
            (ShapeName::Capsule, &[radius, length]) => Geometry::Capsule { radius, length },
            _ => return Err(bad()),
        })
    }

    /// Where the obstacle sits in the world.
    pub fn origin(&self) -> Origin {
        Origin {
            xyz: self.xyz,
            rpy: self.rpy,
        }
    }

    /// Its name, or "obstacle N" (from 1) when none is given.
    pub fn label(&self, i: usize) -> String {
        if self.name.is_empty() {
            format!("obstacle {}", i + 1)
        } else {
            self.name.clone()
        }
    }
}
