//! MJCF (MuJoCo's format) into the same checked [`ArmModel`] the URDF path
//! builds. `mjcf-rs` reads the file (includes, default classes, angle
//! units and Euler sequences resolved); this module turns its body tree
//! into URDF links and joints and hands them to the URDF path's checks
//! (`tree::build`: roots, locks, inertia checks, folding of welded bodies),
//! so that the two formats cannot drift apart. What URDF cannot say
//! (armature, the home keyframe, actuator limits) is set on the result;
//! the files beside this one hold each part: includes (`mjcf_include`,
//! and which files they may read, `mjcf_include_file`), what the parser
//! must not meet (`mjcf_scan`), inertia from geoms (`mjcf_inertia`),
//! actuators (`mjcf_actuators`, `mjcf_joint_force`), the home keyframe
//! (`mjcf_keyframe`), and what is named and not applied (`mjcf_notes`).
//!
//! A MuJoCo joint turns about an anchor `pos` in its body's frame; a URDF
//! joint turns about its child link's origin. Each body's link frame is
//! therefore its body frame moved to its (last) joint's anchor, and what
//! the body holds (inertia, geoms, child bodies) is shifted back by it.
//! Several joints in one body become a chain of massless links.

use std::collections::HashMap;
use std::path::Path;

use mjcf_rs::body::{Body, Geom, GeomType, InertiaSpec, Joint, JointType};
use nalgebra::{Isometry3, Quaternion, UnitQuaternion, Vector3};

use super::inertia::origin_of;
use super::{ArmModel, JointKind, Locks, Origin};
use crate::ModelError;

/// True when the document's root element is `<mujoco>` (MJCF), read past
/// the XML declaration, comments and a doctype.
pub(crate) fn is_mjcf(text: &str) -> bool {
    let mut rest = text.trim_start_matches('\u{feff}').trim_start();
    loop {
        let skip = if rest.starts_with("<?") {
            rest.find("?>").map(|i| i + 2)
        } else if rest.starts_with("<!--") {
            rest.find("-->").map(|i| i + 3)
        } else if rest.starts_with("<!") {
            declaration_end(rest)
        } else {
            break;
        };
        match skip {
            Some(i) => rest = rest[i..].trim_start(),
            None => return false,
        }
    }
    rest.strip_prefix("<mujoco")
        .and_then(|r| r.chars().next())
        .is_some_and(|c| c.is_whitespace() || c == '>' || c == '/')
}

/// Where a `<!…>` declaration ends, past a doctype's internal subset
/// (`<!DOCTYPE mujoco [<!ENTITY …>]>`): an entity bomb in MJCF is then
/// told as MJCF, and refused as one, instead of "not a valid URDF".
fn declaration_end(rest: &str) -> Option<usize> {
    let close = rest.find('>')?;
    match rest[..close].find('[') {
        Some(open) => {
            let subset_end = open + rest[open..].find(']')?;
            rest[subset_end..].find('>').map(|i| subset_end + i + 1)
        }
        None => Some(close + 1),
    }
}

/// Reads an MJCF document whose `<include>`s are relative to `base_dir`.
pub(crate) fn from_str(text: &str, base_dir: &Path, locks: &Locks) -> Result<ArmModel, ModelError> {
    // Inlined first, so that an include anywhere MuJoCo takes one (inside
    // a <body>, as Adroit's) reads as MuJoCo reads it.
    let whole = super::mjcf_include::inline(text, base_dir)?;
    // An included file's body may hold what the main file may not.
    super::mjcf_include::refuse_doctype(&whole)?;
    // mjcf-rs reads an <include> or an <asset><model file> itself,
    // unbounded and from anywhere: none may be left for it.
    super::mjcf_scan::refuse_parser_reads(&whole)?;
    super::mjcf_scan::check_orientations(&whole)?;
    let m = mjcf_rs::Model::from_str(&whole, base_dir)
        .map_err(|e| ModelError::MjcfParse(e.to_string()))?;
    let joint_force = super::mjcf_joint_force::joint_force_limits(&whole, m.compiler.autolimits)?;
    convert(&m, &whole, &joint_force, locks)
}

/// What the conversion learns beside the URDF tree.
struct Converted {
    robot: urdf_rs::Robot,
    /// MJCF joint name → armature.
    armature: HashMap<String, f64>,
    /// MJCF joints in qpos order (keyframes index them so).
    qpos_order: Vec<String>,
    notes: Vec<String>,
}

fn convert(
    m: &mjcf_rs::Model,
    whole: &str,
    joint_force: &HashMap<String, f64>,
    locks: &Locks,
) -> Result<ArmModel, ModelError> {
    let c = tree(m, super::mjcf_inertia::group_range(whole)?)?;
    let mut model = super::tree::build(&c.robot, locks, super::tree::Masses::AsGiven)?;
    for j in &mut model.joints {
        j.armature = c.armature.get(&j.name).copied().unwrap_or(0.0);
    }
    let mut notes = c.notes;
    notes.extend(super::mjcf_actuators::actuators(m, &mut model)?);
    // A joint's actuatorfrcrange clamps whatever drives it.
    for j in model
        .joints
        .iter_mut()
        .filter(|j| j.kind != JointKind::Fixed)
    {
        if let Some(&f) = joint_force.get(&j.name) {
            let what = format!(
                "actuatorfrcrange (its larger end in size {})",
                super::mjcf_actuators::number(f)
            );
            let f = super::mjcf_actuators::usable_limit(f, &what).map_err(|reason| {
                ModelError::MjcfRefused {
                    element: format!("<joint name='{}'>", j.name),
                    reason,
                }
            })?;
            j.effort = Some(j.effort.map_or(f, |e| e.min(f)));
        }
    }
    model.home = super::mjcf_keyframe::home(m, &model, &c.qpos_order)?;
    notes.extend(super::mjcf_notes::unapplied(m, whole));
    notes.append(&mut model.notes);
    model.notes = notes;
    Ok(model)
}

fn iso_of(p: &mjcf_rs::Pose) -> Isometry3<f64> {
    let (q, t) = (p.rotation, p.translation);
    Isometry3::from_parts(
        Vector3::new(t.x, t.y, t.z).into(),
        UnitQuaternion::from_quaternion(Quaternion::new(q.w, q.x, q.y, q.z)),
    )
}

fn pose(o: Origin) -> urdf_rs::Pose {
    urdf_rs::Pose {
        xyz: urdf_rs::Vec3(o.xyz),
        rpy: urdf_rs::Vec3(o.rpy),
    }
}

/// The body tree as URDF links and joints; the world body is link `world`.
fn tree(m: &mjcf_rs::Model, groups: [i32; 2]) -> Result<Converted, ModelError> {
    let mut c = Converted {
        robot: urdf_rs::Robot {
            name: m.name.clone().unwrap_or_else(|| "mjcf".into()),
            version: None,
            links: Vec::new(),
            joints: Vec::new(),
            materials: Vec::new(),
        },
        armature: HashMap::new(),
        qpos_order: Vec::new(),
        notes: Vec::new(),
    };
    // Each body's link: its name and the anchor its link frame sits at.
    let mut link_of: Vec<(String, Vector3<f64>)> = Vec::with_capacity(m.bodies.len());
    // Whether a joint lies between the body and the world.
    let mut moves: Vec<bool> = Vec::with_capacity(m.bodies.len());
    for (id, entry) in m.bodies.iter().enumerate() {
        let b = &entry.body;
        let Some(parent) = entry.parent else {
            c.robot.links.push(link(
                (m, groups),
                "world",
                b,
                Vector3::zeros(),
                Weld::World,
                &mut c.notes,
            )?);
            link_of.push(("world".into(), Vector3::zeros()));
            moves.push(false);
            continue;
        };
        let name = super::mjcf_notes::body_name(b, id);
        let (parent_link, parent_anchor) = link_of
            .get(parent)
            .cloned()
            .ok_or_else(|| ModelError::MjcfParse(format!("body '{name}' precedes its parent")))?;
        let placed = iso_of(&b.pose);
        let anchor = joints(
            m,
            &mut c,
            &name,
            b,
            parent == 0,
            (&parent_link, parent_anchor, &placed),
        )?;
        let moving = moves.get(parent).copied().unwrap_or(false) || !b.joints.is_empty();
        let weld = if moving { Weld::Moves } else { Weld::Fixed };
        let l = match link((m, groups), &name, b, anchor, weld, &mut c.notes) {
            // A body welded to the world moves nothing: its mass does not
            // matter, so a mesh it would take it from is not needed.
            Err(ModelError::MjcfRefused { element, .. }) if !moving => {
                c.notes.push(format!(
                    "{element}: its mass would come from a mesh, which is not read; the body is welded to the world, so its mass does not change the dynamics"
                ));
                link((m, groups), &name, b, anchor, Weld::World, &mut c.notes)?
            }
            other => other?,
        };
        c.robot.links.push(l);
        link_of.push((name, anchor));
        moves.push(moving);
    }
    Ok(c)
}

/// The joints from the parent link to body `name`'s link (a chain of
/// massless links when the body has several; a fixed joint when none),
/// and the anchor of its last joint in the body frame.
fn joints(
    m: &mjcf_rs::Model,
    c: &mut Converted,
    name: &str,
    b: &Body,
    on_world: bool,
    (parent_link, parent_anchor, placed): (&str, Vector3<f64>, &Isometry3<f64>),
) -> Result<Vector3<f64>, ModelError> {
    // The body frame in the parent's link frame.
    let mut at = Isometry3::from_parts(
        (placed.translation.vector - parent_anchor).into(),
        placed.rotation,
    );
    let mut from = parent_link.to_string();
    let mut anchor = Vector3::zeros();
    if b.joints.is_empty() {
        c.robot.joints.push(urdf_joint(
            format!("{name}_weld"),
            urdf_rs::JointType::Fixed,
            (&from, name),
            origin_of(&at),
            None,
        ));
        return Ok(anchor);
    }
    for (k, j) in b.joints.iter().enumerate() {
        let jname = j.name.clone().unwrap_or_else(|| format!("{name}_joint{k}"));
        let element = format!("<joint name='{jname}'> in <body name='{name}'>");
        let pos = Vector3::from(j.pos);
        let origin = at
            * Isometry3::translation(pos.x - anchor.x, pos.y - anchor.y, pos.z - anchor.z)
            * reference_shift(j);
        let to = if k + 1 == b.joints.len() {
            name.to_string()
        } else {
            let virtual_link = format!("{name}/{jname}");
            c.robot.links.push(empty_link(&virtual_link));
            virtual_link
        };
        let (kind, limit) = kind_and_limit(m, j, &element, on_world)?;
        let mut joint = urdf_joint(
            jname.clone(),
            kind,
            (&from, &to),
            origin_of(&origin),
            Some(j),
        );
        joint.limit = limit;
        c.robot.joints.push(joint);
        c.armature.insert(jname.clone(), j.armature);
        c.notes.extend(super::mjcf_notes::joint(j, &element));
        c.qpos_order.push(jname);
        at = Isometry3::identity();
        anchor = pos;
        from = to;
    }
    Ok(anchor)
}

/// MuJoCo writes a body at the pose its joint has at q = `ref`: the joint
/// frame is turned (slid) back by `ref` along the axis, so that q is
/// MuJoCo's qpos, the range and keyframes as written.
fn reference_shift(j: &Joint) -> Isometry3<f64> {
    let Some(axis) = nalgebra::Unit::try_new(Vector3::from(j.axis), 1e-12) else {
        return Isometry3::identity();
    };
    match j.type_ {
        JointType::Hinge => Isometry3::from_parts(
            Vector3::zeros().into(),
            UnitQuaternion::from_axis_angle(&axis, -j.ref_),
        ),
        JointType::Slide => {
            Isometry3::translation(-j.ref_ * axis.x, -j.ref_ * axis.y, -j.ref_ * axis.z)
        }
        JointType::Ball | JointType::Free => Isometry3::identity(),
    }
}

/// The URDF kind and limits of an MJCF joint; ball and free joints refused.
fn kind_and_limit(
    m: &mjcf_rs::Model,
    j: &Joint,
    element: &str,
    on_world: bool,
) -> Result<(urdf_rs::JointType, urdf_rs::JointLimit), ModelError> {
    let refuse = |reason: String| ModelError::MjcfRefused {
        element: element.to_string(),
        reason,
    };
    let limited = j.limited.resolve(m.compiler.autolimits, j.range.is_some());
    let range = j.range.filter(|_| limited);
    let kind = match (j.type_, range) {
        (JointType::Free, _) if on_world => {
            return Err(refuse(
                "a free joint on a body of the world is a floating base; the testbed's arms are fixed to the world (remove it to weld the base)".into(),
            ));
        }
        (JointType::Free | JointType::Ball, _) => {
            return Err(refuse(format!(
                "a {} joint has {} degrees of freedom; the testbed simulates hinge and slide joints only (lock it by replacing it with a hinge, or remove it to weld the body)",
                if j.type_ == JointType::Free {
                    "free"
                } else {
                    "ball"
                },
                if j.type_ == JointType::Free { 6 } else { 3 }
            )));
        }
        (JointType::Slide, None) => {
            return Err(refuse(
                "a slide joint without a range has no scale to choose a posture or an envelope from: give it range (and limited=\"true\" without autolimits)".into(),
            ));
        }
        (JointType::Hinge, None) => urdf_rs::JointType::Continuous,
        (JointType::Hinge, Some(_)) => urdf_rs::JointType::Revolute,
        (JointType::Slide, Some(_)) => urdf_rs::JointType::Prismatic,
    };
    let (lower, upper) = range.map_or((0.0, 0.0), |r| (r[0], r[1]));
    Ok((
        kind,
        urdf_rs::JointLimit {
            lower,
            upper,
            ..urdf_rs::JointLimit::default()
        },
    ))
}

fn urdf_joint(
    name: String,
    joint_type: urdf_rs::JointType,
    (parent, child): (&str, &str),
    origin: Origin,
    j: Option<&Joint>,
) -> urdf_rs::Joint {
    urdf_rs::Joint {
        name,
        joint_type,
        origin: pose(origin),
        parent: urdf_rs::LinkName {
            link: parent.into(),
        },
        child: urdf_rs::LinkName { link: child.into() },
        axis: urdf_rs::Axis {
            xyz: urdf_rs::Vec3(j.map_or([1.0, 0.0, 0.0], |j| j.axis)),
        },
        limit: urdf_rs::JointLimit::default(),
        calibration: None,
        // frictionloss is MuJoCo's dry friction, the URDF's `friction`.
        dynamics: j.map(|j| urdf_rs::Dynamics {
            damping: j.damping,
            friction: j.frictionloss,
        }),
        mimic: None,
        safety_controller: None,
    }
}

fn empty_link(name: &str) -> urdf_rs::Link {
    urdf_rs::Link {
        name: name.into(),
        inertial: urdf_rs::Inertial::default(),
        visual: Vec::new(),
        collision: Vec::new(),
    }
}

/// How a body hangs from the world.
#[derive(Clone, Copy, PartialEq)]
enum Weld {
    /// The world body itself (or one whose mass is left out).
    World,
    /// Welded to the world through fixed joints only.
    Fixed,
    /// A joint lies between it and the world.
    Moves,
}

/// A body's link: its mass properties and collision primitives in its
/// link frame (the body frame moved to `anchor`). Meshes are never read:
/// a body whose mass MuJoCo would take from a mesh is refused by name.
fn link(
    (m, groups): (&mjcf_rs::Model, [i32; 2]),
    name: &str,
    b: &Body,
    anchor: Vector3<f64>,
    weld: Weld,
    notes: &mut Vec<String>,
) -> Result<urdf_rs::Link, ModelError> {
    use mjcf_rs::compiler::InertiaFromGeom;
    let shift = Isometry3::translation(-anchor.x, -anchor.y, -anchor.z);
    let mut l = empty_link(name);
    l.collision = b
        .geoms
        .iter()
        .filter(|g| g.contype != 0 || g.conaffinity != 0)
        .filter_map(|g| collision(g, &shift))
        .collect();
    if weld == Weld::World {
        return Ok(l);
    }
    let from_geoms = match (&b.inertial, m.compiler.inertia_from_geom) {
        (_, InertiaFromGeom::True) | (None, InertiaFromGeom::Auto) => true,
        (Some(_), _) => false,
        (None, InertiaFromGeom::False) => return Ok(l),
    };
    let (mass, at, tensor) = if from_geoms {
        // Only geoms in <compiler inertiagrouprange> weigh anything.
        let weighed: Vec<Geom> = (b.geoms.iter())
            .filter(|g| (groups[0]..=groups[1]).contains(&g.group))
            .cloned()
            .collect();
        let sum = super::mjcf_inertia::from_geoms(name, &weighed)?;
        (
            sum.mass,
            super::inertia::iso(&sum.inertial_origin),
            sum.inertia,
        )
    } else {
        let Some(i) = &b.inertial else {
            return Ok(l);
        };
        let t = match i.inertia {
            InertiaSpec::Diagonal([a, b, c]) => [a, 0.0, 0.0, b, 0.0, c],
            // MJCF orders fullinertia ixx iyy izz ixy ixz iyz.
            InertiaSpec::Full([xx, yy, zz, xy, xz, yz]) => [xx, xy, xz, yy, yz, zz],
        };
        // A body welded to the world moves nothing: its tensor is not used.
        let t = match weld {
            Weld::Moves => {
                let (t, note) = super::mjcf_inertia::balanced(name, t, m.compiler.balance_inertia)?;
                notes.extend(note);
                t
            }
            Weld::Fixed | Weld::World => t,
        };
        (i.mass, iso_of(&i.pose), t)
    };
    let [ixx, ixy, ixz, iyy, iyz, izz] = tensor;
    l.inertial = urdf_rs::Inertial {
        origin: pose(origin_of(&(shift * at))),
        mass: urdf_rs::Mass { value: mass },
        inertia: urdf_rs::Inertia {
            ixx,
            ixy,
            ixz,
            iyy,
            iyz,
            izz,
        },
    };
    Ok(l)
}

/// A geom that collides as a URDF collision element: primitives as
/// shapes, meshes by name (listed, not shapes); ellipsoids, planes and
/// height fields are not URDF shapes and are left out.
fn collision(g: &Geom, shift: &Isometry3<f64>) -> Option<urdf_rs::Collision> {
    let (at, s) = super::mjcf_inertia::placed(g);
    let geometry = match g.type_ {
        GeomType::Sphere => urdf_rs::Geometry::Sphere { radius: s[0] },
        GeomType::Capsule => urdf_rs::Geometry::Capsule {
            radius: s[0],
            length: 2.0 * s[1],
        },
        GeomType::Cylinder => urdf_rs::Geometry::Cylinder {
            radius: s[0],
            length: 2.0 * s[1],
        },
        GeomType::Box => urdf_rs::Geometry::Box {
            size: urdf_rs::Vec3([2.0 * s[0], 2.0 * s[1], 2.0 * s[2]]),
        },
        GeomType::Mesh => urdf_rs::Geometry::Mesh {
            filename: g.mesh.clone().unwrap_or_default(),
            scale: None,
        },
        _ => return None,
    };
    Some(urdf_rs::Collision {
        name: g.name.clone(),
        origin: pose(origin_of(&(shift * at))),
        geometry,
    })
}
