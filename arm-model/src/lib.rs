//! A URDF arm read into a checked, engine-neutral description, and its
//! rigid-body dynamics computed from that description alone. An MJCF
//! (MuJoCo) file, told by its `<mujoco>` root, is read into the same
//! description through the same checks (`mjcf.rs`, #47).
//!
//! Where it sits: under both ends of the loop. The plant (`plant-rapier`)
//! builds its Rapier multibody from an [`ArmModel`]; the model-based
//! reference laws of the controller (`pd-gravity`, `ctc`) evaluate M, C and
//! G with [`dynamics`], a recursive Newton–Euler written from the same data
//! and sharing nothing with Rapier. Parsing and checking happen here, once,
//! so that every consumer sees a tree it can use, and every problem is
//! reported with the link or joint it concerns. The loader is as lenient as
//! the format is in practice: a link of zero or negligible mass contributes
//! nothing whatever inertia it lists, the fixed root's mass properties are
//! irrelevant, `<mimic>` joints become coupled joints, and joints a scenario
//! locks become fixed ones. Undeclared XML namespace prefixes are read as
//! declared, a joint hanging from an undefined `world` link hangs from the
//! fixed world, and a light link (under 1 % of the heaviest link's mass)
//! whose inertia is malformed keeps its mass and centre of mass with a
//! sphere's tensor; each is said in [`ArmModel::notes`] or
//! [`ArmModel::ignored`].
//!
//! ```
//! use arm_model::{ArmModel, TWO_LINK_URDF, dynamics::Dynamics};
//! let model = ArmModel::from_urdf_str(TWO_LINK_URDF).unwrap();
//! let mut dynamics = Dynamics::new(&model, 1.0);
//! let g = dynamics.gravity(&[0.0, 0.0]).to_vec();
//! assert!(g[0] > 0.0); // holding the arm level takes a positive shoulder torque
//! ```

mod bounded_read;
mod collision;
mod diagnose;
pub mod dynamics;
mod error;
mod extra_elements;
mod file_refs;
mod fold;
mod inertia;
mod link_children;
mod mjcf;
mod mjcf_actuators;
mod mjcf_include;
mod mjcf_include_file;
mod mjcf_inertia;
mod mjcf_joint_force;
mod mjcf_keyframe;
mod mjcf_notes;
mod mjcf_scan;
mod parse;
mod prefixes;
mod root_element;
mod tree;
mod xml_depth;

use std::collections::BTreeMap;

pub use collision::{CollisionShape, Geometry};
pub use error::ModelError;
pub use inertia::iso;
pub use mjcf_actuators::MAX_MJCF_EFFORT;
pub use mjcf_include::MAX_INCLUDED_FILES;

/// The most links (and joints) a URDF may have: real arms have tens.
pub const MAX_LINKS: usize = 1000;

/// The largest URDF document read, in bytes (16 MiB, the cap
/// `wire::MAX_URDF_BYTES` puts on a URDF file). Real arms' URDFs are
/// 10–100 kB (the shipped ones are under 14 kB). Here it also bounds text
/// that came from elsewhere: a log's attachment of 60 MB was read and took
/// 101 s to be refused (#48 item 8).
pub const MAX_URDF_BYTES: usize = 16 << 20;

/// The most attributes one element may have. URDF's elements have at most
/// six (`<inertia>`); the XML readers compare each attribute with every
/// earlier one, so a tag of 100 000 took minutes (#48 item 8).
pub const MAX_ATTRIBUTES: usize = 256;

/// The paper's two-link arm (SPEC §1), embedded so the default scenario
/// needs no files.
pub const TWO_LINK_URDF: &str = include_str!("../../robots/two_link.urdf");

/// A rigid transform from a URDF `<origin xyz rpy>`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Origin {
    /// Translation, m.
    pub xyz: [f64; 3],
    /// Fixed-axis roll, pitch, yaw, rad.
    pub rpy: [f64; 3],
}

/// How a joint moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the axis between limits.
    Revolute,
    /// Rotation about the axis without limits.
    Continuous,
    /// Translation along the axis.
    Prismatic,
    /// No motion: the child moves with the parent.
    Fixed,
}

impl JointKind {
    /// True for the kinds that move (driven or coupled).
    pub fn is_actuated(self) -> bool {
        !matches!(self, JointKind::Fixed)
    }

    /// The unit of this joint's effort (a force for a slide, else a torque).
    pub fn effort_unit(self) -> &'static str {
        match self {
            JointKind::Prismatic => "N",
            JointKind::Revolute | JointKind::Continuous | JointKind::Fixed => "N m",
        }
    }

    /// The URDF spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
            JointKind::Fixed => "fixed",
        }
    }
}

/// One link's mass properties.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkInfo {
    /// URDF link name.
    pub name: String,
    /// Mass, kg (0 for a link with no `<inertial>`, or one ignored).
    pub mass: f64,
    /// Pose of the inertial frame in the link frame.
    pub inertial_origin: Origin,
    /// Inertia tensor about the COM in the inertial frame, kg m²,
    /// as [ixx, ixy, ixz, iyy, iyz, izz].
    pub inertia: [f64; 6],
    /// Its `<collision>` primitives (and those of links folded into it).
    pub collisions: Vec<CollisionShape>,
    /// Mesh collision elements (not contact shapes), named.
    pub skipped_collisions: Vec<String>,
    /// Collision primitives that cannot be shapes, each with why.
    pub bad_collisions: Vec<String>,
}

/// A URDF `<mimic joint multiplier offset>`: q = multiplier · q_leader + offset.
#[derive(Debug, Clone, PartialEq)]
pub struct MimicSpec {
    /// The joint followed.
    pub joint: String,
    /// Multiplier (default 1).
    pub multiplier: f64,
    /// Offset (default 0).
    pub offset: f64,
}

/// One joint.
#[derive(Debug, Clone, PartialEq)]
pub struct JointInfo {
    /// URDF joint name.
    pub name: String,
    /// Its kind.
    pub kind: JointKind,
    /// Index of the parent link in [`ArmModel::links`].
    pub parent: usize,
    /// Index of the child link.
    pub child: usize,
    /// Pose of the joint frame (= child link frame at q = 0) in the parent link frame.
    pub origin: Origin,
    /// Unit axis in the joint frame.
    pub axis: [f64; 3],
    /// Position limits (lower, upper) for revolute and prismatic joints.
    pub limits: Option<(f64, f64)>,
    /// Effort limit (N m or N) when the URDF gives a positive one.
    pub effort: Option<f64>,
    /// `<dynamics damping>`: viscous, N m s/rad or N s/m (0 when absent).
    pub damping: f64,
    /// `<dynamics friction>`: dry friction, N m or N (0 when absent).
    pub friction: f64,
    /// `<mimic>` as written.
    pub mimic: Option<MimicSpec>,
    /// Rotor inertia reflected to the joint (MJCF `armature`), kg m² or
    /// kg, added to M(q)'s diagonal; 0 from a URDF, which has none (there
    /// the scenario's `[plant] armature` gives it).
    pub armature: f64,
}

/// A joint that moves with a controlled joint and is not controlled itself.
#[derive(Debug, Clone, PartialEq)]
pub struct MimicJoint {
    /// Index in [`ArmModel::joints`].
    pub joint: usize,
    /// The controlled joint it follows, as an index into [`ArmModel::actuated`]
    /// (a chain of mimics is resolved to its first leader).
    pub leader: usize,
    /// q = multiplier · q_leader + offset.
    pub multiplier: f64,
    /// Offset, rad or m.
    pub offset: f64,
}

/// A joint held at one position: simulated as a fixed joint.
#[derive(Debug, Clone, PartialEq)]
pub struct LockedJoint {
    /// URDF joint name.
    pub name: String,
    /// Where it is held, rad or m.
    pub position: f64,
    /// The locked joint this one mimics, when it is locked for that reason.
    pub follows: Option<String>,
}

/// A link whose mass properties the loader set to zero, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct IgnoredLink {
    /// URDF link name.
    pub name: String,
    /// The mass it listed, kg.
    pub mass: f64,
    /// Why it contributes nothing.
    pub reason: String,
}

/// A checked arm: a tree of links rooted at one fixed link.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmModel {
    /// The robot's name.
    pub name: String,
    /// Links in file order.
    pub links: Vec<LinkInfo>,
    /// Joints in file order.
    pub joints: Vec<JointInfo>,
    /// Index of the root link (fixed to the world).
    pub root: usize,
    /// Joint indices depth-first from the root (parents before children,
    /// siblings in file order).
    pub topological: Vec<usize>,
    /// Indices of the controlled joints in tree order (depth-first from the
    /// root): the joint order used everywhere in the testbed. Mimic and
    /// locked joints are not among them.
    pub actuated: Vec<usize>,
    /// Joints coupled to a controlled joint by `<mimic>`.
    pub mimic: Vec<MimicJoint>,
    /// Joints held still (by the scenario, or because they mimic one that is).
    pub locked: Vec<LockedJoint>,
    /// Links whose listed mass properties were ignored.
    pub ignored: Vec<IgnoredLink>,
    /// What the loader accepted that a user should know (slightly
    /// unphysical inertias, say).
    pub notes: Vec<String>,
    /// Fixed joints folded into their parent link, described for users.
    pub merged: Vec<String>,
    /// Links folded away by a merge: where each one now sits, so that a
    /// scenario can still name it (a payload at a tool link, say).
    pub merged_links: Vec<MergedLink>,
    /// Every link's parent link as the file gives it (child → parent, by
    /// name), before fixed joints are folded: the tree a viewer draws
    /// (`/tf`), where `joints` hang a joint from the link its parent was
    /// folded into.
    pub tree_parents: BTreeMap<String, String>,
    /// The pose the file names as the arm's home, per controlled joint
    /// (MJCF keyframe `home`, or its first key); None from a URDF.
    pub home: Option<Vec<f64>>,
}

/// A link that a fixed joint folded into another one.
#[derive(Debug, Clone, PartialEq)]
pub struct MergedLink {
    /// The URDF name of the folded link.
    pub name: String,
    /// Index of the link it is now part of.
    pub into: usize,
    /// Its frame in that link's frame.
    pub origin: Origin,
    /// The link its joint hangs it from in the file (a link folded away
    /// itself, perhaps: panda_hand hangs from panda_link8, which is part of
    /// panda_link7).
    pub parent: String,
    /// Its frame in `parent`'s frame: the joint's origin (with a locked
    /// joint's held position).
    pub joint_origin: Origin,
}

/// Joint name → position at which a scenario holds it.
pub type Locks = BTreeMap<String, f64>;

impl ArmModel {
    /// Parses and checks a URDF document.
    pub fn from_urdf_str(text: &str) -> Result<Self, ModelError> {
        Self::from_urdf_str_locked(text, &Locks::new())
    }

    /// Parses and checks a URDF document with the joints in `locks` held
    /// at the given positions.
    pub fn from_urdf_str_locked(text: &str, locks: &Locks) -> Result<Self, ModelError> {
        if text.len() > MAX_URDF_BYTES {
            return Err(ModelError::TooLarge {
                bytes: text.len(),
                cap: MAX_URDF_BYTES,
            });
        }
        if let Some(wide) = xml_depth::widest_tag(text, MAX_ATTRIBUTES) {
            return Err(ModelError::TooManyAttributes {
                element: wide.element,
                line: wide.line,
                count: wide.count,
                cap: MAX_ATTRIBUTES,
            });
        }
        root_element::check(text)?;
        // Chosen by content, so every place that takes a robot file takes
        // MJCF too; text names no other file (see `self_contained`).
        let is_mjcf = mjcf::is_mjcf(text);
        let deepest = xml_depth::depth(text, xml_depth::MAX_XML_DEPTH);
        if deepest > xml_depth::MAX_XML_DEPTH {
            return Err(too_deep(is_mjcf));
        }
        if is_mjcf {
            mjcf_include::refuse_includes(text)?;
            return mjcf::from_str(text, std::path::Path::new("."), locks);
        }
        let (text, undeclared) = prefixes::declare_undeclared(text);
        // What is read past goes first: a removed <axis> needs no xyz.
        let (text, read_past) = extra_elements::remove_extra(&text);
        let (text, unnamed_files) = file_refs::fill_missing(&text);
        let (text, gathered_links) = link_children::gather(&text);
        let robot = urdf_rs::read_from_string(&text).map_err(|e| {
            let said = e.to_string();
            ModelError::Parse(diagnose::diagnose(&text, &said).unwrap_or(said))
        })?;
        let mut model = tree::build(&robot, locks, tree::Masses::Urdf)?;
        for (element, n) in unnamed_files.iter().rev() {
            let note = if *element == "limit" {
                format!(
                    "{n} joint <limit> element(s) without a velocity: read as none given \
                     (the testbed uses no joint velocity limit)"
                )
            } else if *element == "material" {
                format!(
                    "{n} <material> element(s) without a name: read with an empty name \
                     (materials do not change the dynamics)"
                )
            } else if *element == "axis" {
                format!(
                    "{n} <axis> element(s) without an xyz: ignored on fixed joints, as urdfdom \
                     does (a moving joint needs one)"
                )
            } else {
                format!(
                    "{n} <{element}> element(s) without a filename: read as naming no file \
                     (they do not change the dynamics)"
                )
            };
            model.notes.insert(0, note);
        }
        if gathered_links > 0 {
            model.notes.insert(
                0,
                format!(
                    "{gathered_links} link(s) list children of one kind apart (e.g. <visual> and \
                     <collision> interleaved): gathered by kind, each in its own order, as \
                     urdfdom reads them"
                ),
            );
        }
        for note in read_past.into_iter().rev() {
            model.notes.insert(0, note);
        }
        if !undeclared.is_empty() {
            model.notes.insert(
                0,
                format!(
                    "XML namespace prefix {} used without an xmlns declaration: read as declared (what it marks is ignored, as other URDF readers do)",
                    undeclared
                        .iter()
                        .map(|p| format!("'{p}'"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            );
        }
        Ok(model)
    }

    /// The robot file's text as the model reads it again from text alone:
    /// an MJCF document's `<include>`s inlined (paths relative to `dir`,
    /// the main file's folder, as MuJoCo takes them); a URDF unchanged.
    pub fn self_contained(text: &str, dir: &std::path::Path) -> Result<String, ModelError> {
        if mjcf::is_mjcf(text) {
            mjcf_include::inline(text, dir)
        } else {
            Ok(text.to_string())
        }
    }

    /// Reads an MJCF file (its `<include>`s relative to its folder) with
    /// the joints in `locks` held; errors name the file. The file and its
    /// includes are read as a scenario reads a robot file: a regular file
    /// of at most [`MAX_URDF_BYTES`], through the same checks as text.
    pub fn from_mjcf_file(path: &std::path::Path, locks: &Locks) -> Result<Self, ModelError> {
        let text = bounded_read::read(path, MAX_URDF_BYTES as u64)
            .map_err(|e| ModelError::MjcfParse(format!("{}: {e}", path.display())))?;
        let dir = path.parent().unwrap_or(std::path::Path::new("."));
        Self::mjcf_text_of_file(&text, dir, locks).map_err(|e| match e {
            ModelError::MjcfParse(why) => {
                ModelError::MjcfParse(format!("{}: {why}", path.display()))
            }
            ModelError::MjcfRefused { element, reason } => ModelError::MjcfRefused {
                element: format!("{element} (in {})", path.display()),
                reason,
            },
            other => other,
        })
    }

    /// An MJCF file's text, its includes inlined from `dir`, read as text.
    fn mjcf_text_of_file(
        text: &str,
        dir: &std::path::Path,
        locks: &Locks,
    ) -> Result<Self, ModelError> {
        if !mjcf::is_mjcf(text) {
            root_element::check(text)?;
            return Err(ModelError::MjcfParse(
                "the root element is not <mujoco>: not an MJCF file".into(),
            ));
        }
        Self::from_urdf_str_locked(&mjcf_include::inline(text, dir)?, locks)
    }

    /// The link called `name` (a merged one too): the index of the body it
    /// is part of and its frame in that body's link frame.
    pub fn locate_link(&self, name: &str) -> Option<(usize, Origin)> {
        if let Some(i) = self.links.iter().position(|l| l.name == name) {
            return Some((i, Origin::default()));
        }
        self.merged_links
            .iter()
            .find(|m| m.name == name)
            .map(|m| (m.into, m.origin))
    }

    /// Names of every link a scenario may name: the URDF's, merged ones included.
    pub fn link_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self.links.iter().map(|l| l.name.clone()).collect();
        names.extend(self.merged_links.iter().map(|m| m.name.clone()));
        names
    }

    /// Number of controlled joints.
    pub fn dof(&self) -> usize {
        self.actuated.len()
    }

    /// Names of the controlled joints, in order.
    pub fn joint_names(&self) -> Vec<String> {
        self.actuated
            .iter()
            .map(|&i| self.joints[i].name.clone())
            .collect()
    }

    /// Total mass of the links that move (every link but the root).
    pub fn moving_mass(&self) -> f64 {
        self.links
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != self.root)
            .map(|(_, l)| l.mass)
            .sum()
    }

    /// Mass carried by `link` and everything below it.
    pub fn subtree_mass(&self, link: usize) -> f64 {
        self.links[link].mass
            + self
                .joints
                .iter()
                .filter(|j| j.parent == link)
                .map(|j| self.subtree_mass(j.child))
                .sum::<f64>()
    }

    /// Controlled joints that move no mass at all: their acceleration is
    /// undefined, so the plant refuses them unless they are locked.
    pub fn joints_moving_no_mass(&self) -> Vec<String> {
        self.actuated
            .iter()
            .filter(|&&ji| self.subtree_mass(self.joints[ji].child) <= 0.0)
            .map(|&ji| self.joints[ji].name.clone())
            .collect()
    }

    /// Whether any joint (controlled or mimic) has URDF damping or friction.
    pub fn has_urdf_dynamics(&self) -> bool {
        self.moving_joints()
            .any(|ji| self.joints[ji].damping != 0.0 || self.joints[ji].friction != 0.0)
    }

    /// Every joint that moves: the controlled ones, then the mimic ones.
    pub fn moving_joints(&self) -> impl Iterator<Item = usize> + '_ {
        self.actuated
            .iter()
            .copied()
            .chain(self.mimic.iter().map(|m| m.joint))
    }
}

/// Nesting past [`xml_depth::MAX_XML_DEPTH`], named in the file's format.
fn too_deep(is_mjcf: bool) -> ModelError {
    let max = xml_depth::MAX_XML_DEPTH;
    match is_mjcf {
        true => ModelError::MjcfParse(format!(
            "elements are nested more than {max} deep (a model's elements nest a few levels)"
        )),
        false => ModelError::Parse(format!(
            "elements are nested more than {max} deep: not a URDF (a robot's elements nest a \
             few levels)"
        )),
    }
}

#[cfg(test)]
mod tests;
