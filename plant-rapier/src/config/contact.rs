//! `[plant.contact]`: the arm's links touch obstacles in its workspace
//! through Rapier's contact solver. Off unless an obstacle (or contact
//! between the arm's own links) is written; the articulated engine refuses
//! it by name, since it integrates joint coordinates without a contact
//! solver.

use arm_model::{Geometry, Origin};
use serde::{Deserialize, Serialize};

use super::{invalid, short};
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
    /// Free bodies the arm grasps and releases (a pick and place).
    pub object: Vec<ContactObject>,
}

impl Default for ContactConfig {
    fn default() -> Self {
        Self {
            restitution: 0.0,
            friction: 0.5,
            self_contact: false,
            obstacle: Vec::new(),
            object: Vec::new(),
        }
    }
}

/// A free rigid body that a link grasps at one time and releases at
/// another: it rests on the obstacles before, rides on the link (its mass
/// and inertia part of the link's) while grasped, and falls after.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactObject {
    /// A name for errors (default: "object N").
    #[serde(default)]
    pub name: String,
    /// `box`, `sphere`, `cylinder` or `capsule`, sized as an obstacle is.
    pub shape: ShapeName,
    /// As an obstacle's `size`, m.
    pub size: Vec<f64>,
    /// Mass, kg (a uniform solid of that shape).
    pub mass: f64,
    /// Where its centre starts, world frame, m.
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Its starting orientation, fixed-axis roll, pitch, yaw, rad.
    #[serde(default)]
    pub rpy: [f64; 3],
    /// The URDF link that grasps it.
    pub link: String,
    /// When the link grasps it, wherever it then is relative to the link, s.
    pub grasp_at_s: f64,
    /// When the link lets it go, s (default: never).
    #[serde(default)]
    pub release_at_s: Option<f64>,
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
        self.obstacle.is_empty() && self.object.is_empty() && !self.self_contact
    }

    /// Checks every entry; errors name the key.
    pub fn validate(&self) -> Result<(), PlantError> {
        // A material with nothing to touch would silently do nothing.
        let d = Self::default();
        for (key, value, default) in [
            ("plant.contact.restitution", self.restitution, d.restitution),
            ("plant.contact.friction", self.friction, d.friction),
        ] {
            if value != default && self.is_off() {
                return Err(invalid(
                    key,
                    value,
                    format!(
                        "left at its default ({default}) without obstacles, objects or self_contact: there is nothing to touch"
                    ),
                ));
            }
        }
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
        for (key, n, max, why) in [
            (
                "plant.contact.obstacle",
                self.obstacle.len(),
                MAX_OBSTACLES,
                "",
            ),
            (
                "plant.contact.object",
                self.object.len(),
                wire::MAX_OBJECTS,
                " (the log carries each one's pose)",
            ),
        ] {
            if n > max {
                return Err(invalid(
                    key,
                    format!("{n} entries"),
                    format!("at most {max}{why}"),
                ));
            }
        }
        self.check_names()?;
        for (i, o) in self.object.iter().enumerate() {
            o.validate(i)?;
        }
        for (i, o) in self.obstacle.iter().enumerate() {
            o.geometry(i)?;
            let key = |k: &str| format!("plant.contact.obstacle[{i}].{k}");
            place(&o.xyz, &o.rpy, &key)?;
        }
        Ok(())
    }
}

impl ContactConfig {
    /// Names are shown in errors, the log's contact diagnostics and the 3D
    /// view, so each names one body: no two alike (obstacles and objects
    /// together, counting the "obstacle N" / "object N" given to unnamed
    /// ones), no control or bidirectional formatting character, at most
    /// [`MAX_NAME_CHARS`] characters.
    fn check_names(&self) -> Result<(), PlantError> {
        let named = self
            .obstacle
            .iter()
            .enumerate()
            .map(|(i, o)| (format!("plant.contact.obstacle[{i}].name"), o.label(i)))
            .chain(
                self.object
                    .iter()
                    .enumerate()
                    .map(|(i, o)| (format!("plant.contact.object[{i}].name"), o.label(i))),
            );
        let mut seen = std::collections::HashMap::new();
        for (key, name) in named {
            let quoted = || {
                let cut: String = name.chars().take(MAX_NAME_CHARS).collect();
                format!("{cut:?}")
            };
            if let Some(c) = wire::forbidden_name_char(&name) {
                return Err(invalid(
                    &key,
                    quoted(),
                    format!(
                        "a name without control or bidirectional formatting characters (it holds {})",
                        wire::describe_char(c)
                    ),
                ));
            }
            let chars = name.chars().count();
            if chars > MAX_NAME_CHARS {
                return Err(invalid(
                    &key,
                    format!("{}… ({chars} characters)", quoted()),
                    format!("a name of at most {MAX_NAME_CHARS} characters"),
                ));
            }
            if let Some(first) = seen.insert(name.clone(), key.clone()) {
                return Err(invalid(
                    &key,
                    quoted(),
                    format!("a name of its own: {first} is named so too"),
                ));
            }
        }
        Ok(())
    }
}

/// The longest obstacle or object name, characters.
pub const MAX_NAME_CHARS: usize = 64;

/// The lightest object taken, kg (a microgram).
pub const MIN_OBJECT_MASS_KG: f64 = 1e-9;

/// More obstacles than a workspace needs is a mistake, not a scene.
const MAX_OBSTACLES: usize = 1000;

impl Obstacle {
    /// The obstacle's shape, checked; `i` is its index for errors.
    pub fn geometry(&self, i: usize) -> Result<Geometry, PlantError> {
        geometry(
            self.shape,
            &self.size,
            &format!("plant.contact.obstacle[{i}].size"),
        )
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

impl ContactObject {
    /// The object's shape, checked; `i` is its index for errors.
    pub fn geometry(&self, i: usize) -> Result<Geometry, PlantError> {
        geometry(
            self.shape,
            &self.size,
            &format!("plant.contact.object[{i}].size"),
        )
    }

    /// Where the object starts in the world.
    pub fn origin(&self) -> Origin {
        Origin {
            xyz: self.xyz,
            rpy: self.rpy,
        }
    }

    /// Its name, or "object N" (from 1) when none is given.
    pub fn label(&self, i: usize) -> String {
        if self.name.is_empty() {
            format!("object {}", i + 1)
        } else {
            self.name.clone()
        }
    }

    fn validate(&self, i: usize) -> Result<(), PlantError> {
        let key = |k: &str| format!("plant.contact.object[{i}].{k}");
        self.geometry(i)?;
        // A microgram at least: 1e-300 kg passed "> 0" and then faulted on
        // every step.
        if !(self.mass >= MIN_OBJECT_MASS_KG && self.mass <= 1e4) {
            return Err(invalid(
                &key("mass"),
                short(self.mass),
                "a mass in [1e-9, 10000] kg",
            ));
        }
        place(&self.xyz, &self.rpy, &key)?;
        if !(self.grasp_at_s.is_finite() && self.grasp_at_s >= 0.0 && self.grasp_at_s <= 1e6) {
            return Err(invalid(
                &key("grasp_at_s"),
                self.grasp_at_s,
                "a time from 0 to 10^6 s",
            ));
        }
        if let Some(r) = self.release_at_s
            && !(r.is_finite() && r > self.grasp_at_s && r <= 1e6)
        {
            return Err(invalid(
                &key("release_at_s"),
                r,
                format!(
                    "a time after grasp_at_s ({} s), up to 10^6 s",
                    self.grasp_at_s
                ),
            ));
        }
        Ok(())
    }
}

/// A pose in the workspace: within 1000 m and turns of 1000 rad; `key`
/// makes a field's key.
fn place(xyz: &[f64; 3], rpy: &[f64; 3], key: &dyn Fn(&str) -> String) -> Result<(), PlantError> {
    for (name, v) in [("xyz", xyz), ("rpy", rpy)] {
        if let Some((i, x)) = v
            .iter()
            .enumerate()
            .find(|(_, x)| x.is_nan() || x.abs() > 1e3)
        {
            return Err(invalid(
                &key(&format!("{name}[{i}]")),
                short(*x),
                "a finite number up to 1000 in size",
            ));
        }
    }
    Ok(())
}

/// A shape from its name and sizes; `key` names the sizes for errors.
fn geometry(shape: ShapeName, s: &[f64], key: &str) -> Result<Geometry, PlantError> {
    let want = match shape {
        ShapeName::Box => "three side lengths > 0, m",
        ShapeName::Sphere => "one radius > 0, m",
        ShapeName::Cylinder | ShapeName::Capsule => "a radius and a length > 0, m",
    };
    let bad = || invalid(key, format!("{s:?}"), want);
    if s.iter().any(|v| !(v.is_finite() && *v > 0.0 && *v <= 1e3)) {
        return Err(bad());
    }
    Ok(match (shape, s) {
        (ShapeName::Box, &[x, y, z]) => Geometry::Box { size: [x, y, z] },
        (ShapeName::Sphere, &[radius]) => Geometry::Sphere { radius },
        (ShapeName::Cylinder, &[radius, length]) => Geometry::Cylinder { radius, length },
        (ShapeName::Capsule, &[radius, length]) => Geometry::Capsule { radius, length },
        _ => return Err(bad()),
    })
}
