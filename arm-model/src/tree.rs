//! The link tree: root and order, mimic chains, locks, which mass
//! matters (fixed joints are folded into their parents in `fold.rs`).

use std::collections::HashMap;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::fold::{Folded, merge_fixed};
use super::inertia::{
    NEGLIGIBLE_MASS_RATIO, PLACEHOLDER_MASS_RATIO, Tensor, arm_size, check_inertia,
    implausible_gyration, iso, origin_of,
};
use super::parse::{joint_info, link_info};
use super::{
    ArmModel, IgnoredLink, JointInfo, JointKind, LinkInfo, LockedJoint, Locks, MimicJoint,
};
use crate::ModelError;

/// How a format's masses are taken.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Masses {
    /// URDF as written in practice: a link of negligible mass is a frame,
    /// and a light link's malformed tensor becomes a sphere's.
    Urdf,
    /// MJCF, whose compiler already refused malformed tensors: every mass
    /// and tensor is taken as given, as MuJoCo takes it (a 1e-8 kg body
    /// still loads the arm there).
    AsGiven,
}

/// Parses, checks and simplifies a URDF robot.
pub(super) fn build(
    robot: &urdf_rs::Robot,
    locks: &Locks,
    masses: Masses,
) -> Result<ArmModel, ModelError> {
    let size = robot.links.len().max(robot.joints.len());
    if size > crate::MAX_LINKS {
        return Err(ModelError::InvalidConfig {
            key: "the URDF's links and joints".into(),
            value: format!("{} links, {} joints", robot.links.len(), robot.joints.len()),
            need: format!("at most {} of each (an arm, not a scene)", crate::MAX_LINKS),
        });
    }
    let mut index = HashMap::new();
    let mut links = Vec::with_capacity(robot.links.len());
    for (i, l) in robot.links.iter().enumerate() {
        if index.insert(l.name.clone(), i).is_some() {
            return Err(ModelError::Duplicate {
                what: "link",
                name: l.name.clone(),
            });
        }
        links.push(link_info(l)?);
    }
    if links.is_empty() {
        return Err(ModelError::NoLinks);
    }
    let mut notes = Vec::new();
    // Drake and Gazebo models weld their base to a `world` they never
    // define; that world is the fixed root every other reader assumes.
    if !index.contains_key(WORLD)
        && let Some(j) = robot.joints.iter().find(|j| j.parent.link == WORLD)
    {
        index.insert(WORLD.to_string(), links.len());
        links.push(LinkInfo {
            name: WORLD.to_string(),
            mass: 0.0,
            inertial_origin: super::Origin::default(),
            inertia: [0.0; 6],
            collisions: Vec::new(),
            skipped_collisions: Vec::new(),
            bad_collisions: Vec::new(),
        });
        notes.push(format!(
            "joint '{}' hangs from link '{WORLD}', which the URDF does not define: taken as the fixed world (the root)",
            j.name
        ));
    }
    let unlimited: Vec<&str> = (robot.joints.iter())
        .filter(|j| j.limit.effort == super::parse::UNLIMITED_EFFORT)
        .map(|j| j.name.as_str())
        .collect();
    if !unlimited.is_empty() {
        notes.push(format!(
            "effort -1 on {}: read as no effort limit (SDF's convention)",
            unlimited.join(", ")
        ));
    }
    let mut joints = Vec::with_capacity(robot.joints.len());
    let mut parent_of: Vec<Option<usize>> = vec![None; links.len()];
    let mut joint_names = HashMap::new();
    for (ji, j) in robot.joints.iter().enumerate() {
        if joint_names.insert(j.name.clone(), ji).is_some() {
            return Err(ModelError::Duplicate {
                what: "joint",
                name: j.name.clone(),
            });
        }
        let info = joint_info(j, &index)?;
        if let Some(other) = parent_of[info.child] {
            return Err(ModelError::TwoParents {
                link: links[info.child].name.clone(),
                first: robot.joints[other].name.clone(),
                second: j.name.clone(),
            });
        }
        parent_of[info.child] = Some(ji);
        joints.push(info);
    }
    let root = find_root(&links, &joints)?;
    depth_first(&links, &joints, root)?;
    let leaders = resolve_mimics(&joints)?;
    let locked = apply_locks(&mut joints, &leaders, locks)?;
    let (ignored, inertia_notes) = settle_masses(&mut links, &joints, root, masses)?;
    notes.extend(inertia_notes);
    let folded = merge_fixed(links, joints);
    let mut model = finish(robot.name.clone(), folded, &leaders, locked, ignored)?;
    notes.extend(free_contradicting_mimic_limits(&mut model));
    model.notes = notes;
    Ok(model)
}

/// Drops the limits of a mimic joint that leave its leader no range: the
/// Robotiq 2F-85's inner finger joints follow `finger_joint` ∈ [0, 0.8]
/// with multiplier −1 but list [0, 0.8757], so their stops would pin the
/// whole gripper at 0. ROS drives mimic joints without their limits; so
/// does the testbed here, and says so. Limits that leave a range are kept.
fn free_contradicting_mimic_limits(model: &mut ArmModel) -> Vec<String> {
    let mut notes = Vec::new();
    for m in &model.mimic {
        let leader = &model.joints[model.actuated[m.leader]];
        let (Some((lo, hi)), Some((a, b))) = (model.joints[m.joint].limits, leader.limits) else {
            continue;
        };
        if m.multiplier == 0.0 {
            continue;
        }
        // The leader's positions the mimic's limits allow.
        let (x, y) = (
            (lo - m.offset) / m.multiplier,
            (hi - m.offset) / m.multiplier,
        );
        let (x, y) = (x.min(y), x.max(y));
        let room = y.min(b) - x.max(a);
        if room <= 1e-9 * (b - a).abs().max(1.0) {
            let (name, leader) = (model.joints[m.joint].name.clone(), leader.name.clone());
            notes.push(format!(
                "mimic joint '{name}': its limits [{lo}, {hi}] leave '{leader}' no range (they allow it [{x:.4}, {y:.4}], its own is [{a}, {b}]): ignored, as ROS drives mimic joints"
            ));
            model.joints[m.joint].limits = None;
        }
    }
    notes
}

/// The link a fixed-base model's root joint conventionally hangs from.
const WORLD: &str = "world";

fn find_root(links: &[LinkInfo], joints: &[JointInfo]) -> Result<usize, ModelError> {
    let mut has_parent = vec![false; links.len()];
    for j in joints {
        has_parent[j.child] = true;
    }
    let roots: Vec<usize> = (0..links.len()).filter(|&i| !has_parent[i]).collect();
    match roots.as_slice() {
        [r] => Ok(*r),
        [] => Err(ModelError::NoRoot),
        many => {
            // A message names a few, not thousands.
            let mut names: Vec<String> = many
                .iter()
                .take(8)
                .map(|&i| links[i].name.clone())
                .collect();
            if many.len() > 8 {
                names.push(format!("and {} more", many.len() - 8));
            }
            Err(ModelError::ManyRoots(names))
        }
    }
}

/// Joints depth-first from the root, siblings in file order; a link never
/// reached sits on a loop.
fn depth_first(
    links: &[LinkInfo],
    joints: &[JointInfo],
    root: usize,
) -> Result<Vec<usize>, ModelError> {
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); links.len()];
    for (ji, j) in joints.iter().enumerate() {
        children[j.parent].push(ji);
    }
    let mut order = Vec::with_capacity(joints.len());
    let mut reached = vec![false; links.len()];
    reached[root] = true;
    let mut stack: Vec<usize> = children[root].iter().rev().copied().collect();
    while let Some(ji) = stack.pop() {
        let child = joints[ji].child;
        if reached[child] {
            continue;
        }
        reached[child] = true;
        order.push(ji);
        stack.extend(children[child].iter().rev());
    }
    match reached.iter().position(|r| !r) {
        Some(i) => Err(ModelError::Cycle {
            link: links[i].name.clone(),
        }),
        None => Ok(order),
    }
}

/// For each mimic joint: the first joint of its chain that mimics none,
/// with the multiplier and offset composed along the chain.
type Leaders = HashMap<String, (String, f64, f64)>;

fn resolve_mimics(joints: &[JointInfo]) -> Result<Leaders, ModelError> {
    let by_name: HashMap<&str, &JointInfo> = joints.iter().map(|j| (j.name.as_str(), j)).collect();
    let mut out = Leaders::new();
    for j in joints {
        let mimic_err = |reason: String| ModelError::Mimic {
            joint: j.name.clone(),
            reason,
        };
        let (mut mult, mut offset) = (1.0, 0.0);
        let mut cur = j;
        let mut steps = 0;
        while let Some(m) = &cur.mimic {
            let Some(leader) = by_name.get(m.joint.as_str()) else {
                return Err(mimic_err(format!(
                    "it follows joint '{}', which does not exist",
                    m.joint
                )));
            };
            if !leader.kind.is_actuated() {
                return Err(mimic_err(format!(
                    "it follows joint '{}', which is fixed",
                    m.joint
                )));
            }
            // q_cur = m·q_leader + o, and q_j = mult·q_cur + offset.
            offset += mult * m.offset;
            mult *= m.multiplier;
            cur = leader;
            steps += 1;
            if steps > joints.len() {
                return Err(mimic_err("its <mimic> chain loops back on itself".into()));
            }
        }
        if steps > 0 {
            out.insert(j.name.clone(), (cur.name.clone(), mult, offset));
        }
    }
    Ok(out)
}

/// Turns locked joints into fixed ones at their positions; a joint that
/// mimics a locked one is locked where the coupling puts it.
fn apply_locks(
    joints: &mut [JointInfo],
    leaders: &Leaders,
    locks: &Locks,
) -> Result<Vec<LockedJoint>, ModelError> {
    let invalid = |name: &str, value: f64, need: String| ModelError::InvalidConfig {
        key: format!("plant.lock.{name}"),
        value: value.to_string(),
        need,
    };
    for (name, &p) in locks {
        let Some(j) = joints.iter().find(|j| &j.name == name) else {
            let movable: Vec<&str> = joints
                .iter()
                .filter(|j| j.kind.is_actuated())
                .map(|j| j.name.as_str())
                .collect();
            return Err(invalid(
                name,
                p,
                format!("a joint of the arm ({})", movable.join(", ")),
            ));
        };
        if !j.kind.is_actuated() {
            return Err(invalid(
                name,
                p,
                "a joint that moves (this one is fixed)".into(),
            ));
        }
        if let Some((leader, ..)) = leaders.get(name) {
            return Err(invalid(
                name,
                p,
                format!("a joint that mimics none: it follows '{leader}' (<mimic>), lock that one"),
            ));
        }
        match j.limits {
            Some((lo, hi)) if !(p >= lo && p <= hi) => {
                return Err(invalid(
                    name,
                    p,
                    format!("within the joint's limits [{lo}, {hi}]"),
                ));
            }
            _ if !p.is_finite() => return Err(invalid(name, p, "a finite number".into())),
            _ => {}
        }
    }
    let mut locked = Vec::new();
    for j in joints.iter_mut().filter(|j| j.kind.is_actuated()) {
        let (position, follows) = match (locks.get(&j.name), leaders.get(&j.name)) {
            (Some(&p), _) => (p, None),
            (None, Some((leader, m, o))) => match locks.get(leader) {
                Some(&p) => (m * p + o, Some(leader.clone())),
                None => continue,
            },
            (None, None) => continue,
        };
        let axis = Vector3::new(j.axis[0], j.axis[1], j.axis[2]);
        let motion = match j.kind {
            JointKind::Prismatic => Isometry3::from_parts(
                Translation3::from(axis * position),
                UnitQuaternion::identity(),
            ),
            _ => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_scaled_axis(axis * position),
            ),
        };
        j.origin = origin_of(&(iso(&j.origin) * motion));
        j.kind = JointKind::Fixed;
        j.mimic = None;
        locked.push(LockedJoint {
            name: j.name.clone(),
            position,
            follows,
        });
    }
    Ok(locked)
}

/// The moment of inertia of a uniform sphere of `mass` kg at water's
/// density (1000 kg/m³): 2/5 m r², r = (3m / 4πρ)^⅓.
fn sphere_moment(mass: f64) -> f64 {
    let r = (3.0 * mass / (4.0 * std::f64::consts::PI * 1000.0)).cbrt();
    0.4 * mass * r * r
}

/// Zeroes what cannot matter (links welded to the fixed root, links of
/// zero or negligible mass) and checks the inertia of every link that moves.
fn settle_masses(
    links: &mut [LinkInfo],
    joints: &[JointInfo],
    root: usize,
    masses: Masses,
) -> Result<(Vec<IgnoredLink>, Vec<String>), ModelError> {
    // Links reached from the root through fixed joints only never move.
    let mut moves = vec![false; links.len()];
    let mut welded = vec![false; links.len()];
    welded[root] = true;
    for ji in depth_first(links, joints, root)? {
        let j = &joints[ji];
        welded[j.child] = welded[j.parent] && j.kind == JointKind::Fixed;
        moves[j.child] = !welded[j.child];
    }
    let heaviest = (0..links.len())
        .filter(|&i| moves[i])
        .map(|i| links[i].mass)
        .fold(0.0, f64::max);
    let threshold = match masses {
        Masses::Urdf => NEGLIGIBLE_MASS_RATIO * heaviest,
        Masses::AsGiven => 0.0,
    };
    // Only what moves: a 5 m pedestal welded to the world is no part of
    // the arm's motion.
    let size = arm_size(
        joints
            .iter()
            .filter(|j| moves[j.child])
            .map(|j| j.origin.xyz),
    );
    let (mut ignored, mut notes) = (Vec::new(), Vec::new());
    for (i, l) in links.iter_mut().enumerate() {
        if !moves[i] {
            l.mass = 0.0;
            l.inertia = [0.0; 6];
            continue;
        }
        if l.mass <= threshold {
            if l.mass > 0.0 || l.inertia.iter().any(|v| *v != 0.0) {
                let reason = if l.mass == 0.0 {
                    "zero mass: the inertia it lists is ignored".to_string()
                } else {
                    format!(
                        "mass {:e} kg is negligible (below {NEGLIGIBLE_MASS_RATIO:e} of the heaviest link's {heaviest} kg): it contributes nothing",
                        l.mass
                    )
                };
                ignored.push(IgnoredLink {
                    name: l.name.clone(),
                    mass: l.mass,
                    reason,
                });
            }
            l.mass = 0.0;
            l.inertia = [0.0; 6];
            continue;
        }
        let checked = check_inertia(&l.name, &l.inertia).map(|t| match t {
            Tensor::Fine(note) => match implausible_gyration(l.mass, &l.inertia, size) {
                Some(reason) => Tensor::Impossible(reason),
                None => Tensor::Fine(note),
            },
            impossible => impossible,
        });
        match checked {
            Ok(Tensor::Fine(note)) => notes.extend(note),
            // A light link (a finger of a few grams to 100 g) with a tensor
            // no body has: its mass and centre of mass still load the arm,
            // so they are kept; its tensor, which matters far less, becomes
            // a uniform sphere's of that mass.
            Ok(Tensor::Impossible(reason)) | Err(ModelError::BadInertia { reason, .. })
                if masses == Masses::Urdf && l.mass < PLACEHOLDER_MASS_RATIO * heaviest =>
            {
                let moment = sphere_moment(l.mass);
                notes.push(format!(
                    "link '{}' ({} kg, under {} % of the heaviest link's {heaviest} kg): its inertia is malformed ({reason}); kept with its mass and centre of mass, its tensor replaced by a uniform sphere's of that mass at water's density ({moment:.3e} kg m² about every axis)",
                    l.name,
                    l.mass,
                    100.0 * PLACEHOLDER_MASS_RATIO
                ));
                l.inertia = [moment, 0.0, 0.0, moment, 0.0, moment];
            }
            // A real link with such a tensor still simulates (M stays
            // positive semi-definite), as Pinocchio and PyBullet take it.
            Ok(Tensor::Impossible(reason)) => notes.push(format!(
                "link '{}': {reason}: simulated as given; correct the tensor if this link's motion matters",
                l.name
            )),
            Err(e) => return Err(e),
        }
    }
    Ok((ignored, notes))
}

/// Orders the simplified tree and sorts its joints into controlled and mimic.
fn finish(
    name: String,
    f: Folded,
    leaders: &Leaders,
    locked: Vec<LockedJoint>,
    ignored: Vec<IgnoredLink>,
) -> Result<ArmModel, ModelError> {
    let root = find_root(&f.links, &f.joints)?;
    let topological = depth_first(&f.links, &f.joints, root)?;
    let actuated: Vec<usize> = topological
        .iter()
        .copied()
        .filter(|&ji| !leaders.contains_key(&f.joints[ji].name))
        .collect();
    if actuated.is_empty() {
        return Err(ModelError::NoActuatedJoints);
    }
    let mut mimic = Vec::new();
    for &ji in &topological {
        let Some((leader, multiplier, offset)) = leaders.get(&f.joints[ji].name) else {
            continue;
        };
        let leader = actuated
            .iter()
            .position(|&a| &f.joints[a].name == leader)
            .ok_or_else(|| ModelError::Mimic {
                joint: f.joints[ji].name.clone(),
                reason: format!("it follows '{leader}', which is not a controlled joint"),
            })?;
        mimic.push(MimicJoint {
            joint: ji,
            leader,
            multiplier: *multiplier,
            offset: *offset,
        });
    }
    Ok(ArmModel {
        name,
        links: f.links,
        joints: f.joints,
        root,
        topological,
        actuated,
        mimic,
        locked,
        ignored,
        notes: Vec::new(),
        merged: f.merged,
        merged_links: f.merged_links,
        tree_parents: f.tree_parents,
        home: None,
    })
}
