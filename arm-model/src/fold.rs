//! Fixed joints folded into their parents: the child's mass, inertia and
//! collision shapes join the parent link, and the child's own joints hang
//! from the parent, so the plant simulates only bodies that move
//! independently.

use super::inertia::{iso, merge_mass, origin_of};
use super::{CollisionShape, JointInfo, JointKind, LinkInfo, MergedLink};

/// The tree once its fixed joints are folded away.
pub(super) struct Folded {
    pub(super) links: Vec<LinkInfo>,
    pub(super) joints: Vec<JointInfo>,
    pub(super) merged: Vec<String>,
    pub(super) merged_links: Vec<MergedLink>,
    pub(super) tree_parents: std::collections::BTreeMap<String, String>,
}

/// Folds every fixed joint into its parent: the child's mass joins the
/// parent link's, and the child's own joints hang from the parent. The
/// plant then simulates only bodies that move independently.
pub(super) fn merge_fixed(mut links: Vec<LinkInfo>, mut joints: Vec<JointInfo>) -> Folded {
    let mut merged = Vec::new();
    let mut merged_links: Vec<MergedLink> = Vec::new();
    let tree_parents = joints
        .iter()
        .map(|j| (links[j.child].name.clone(), links[j.parent].name.clone()))
        .collect();
    // Each fixed joint's own parent and origin, as the file gives them: the
    // loop below re-hangs a joint on whatever its parent was folded into
    // (panda_hand's joint on panda_link7 once panda_link8 is folded there).
    let in_file: std::collections::HashMap<String, (String, super::Origin)> = joints
        .iter()
        .filter(|j| j.kind == JointKind::Fixed)
        .map(|j| {
            let child = links[j.child].name.clone();
            (child, (links[j.parent].name.clone(), j.origin))
        })
        .collect();
    while let Some(ji) = joints.iter().position(|j| j.kind == JointKind::Fixed) {
        let j = joints.remove(ji);
        let (parent, child) = (j.parent, j.child);
        let t = iso(&j.origin);
        let child_link = links[child].clone();
        merge_mass(&mut links[parent], &child_link, &t);
        // The child's contact shapes ride on the parent from now on.
        for c in &child_link.collisions {
            links[parent].collisions.push(CollisionShape {
                origin: origin_of(&(t * iso(&c.origin))),
                geometry: c.geometry,
            });
        }
        links[parent]
            .skipped_collisions
            .extend(child_link.skipped_collisions.iter().cloned());
        links[parent]
            .bad_collisions
            .extend(child_link.bad_collisions.iter().cloned());
        for k in &mut joints {
            if k.parent == child {
                k.parent = parent;
                k.origin = origin_of(&(t * iso(&k.origin)));
            }
        }
        merged.push(format!(
            "{} ({} into {})",
            j.name, child_link.name, links[parent].name
        ));
        for m in &mut merged_links {
            if m.into == child {
                m.into = parent;
                m.origin = origin_of(&(t * iso(&m.origin)));
            }
        }
        let (urdf_parent, joint_origin) = in_file
            .get(&child_link.name)
            .cloned()
            .unwrap_or_else(|| (links[parent].name.clone(), j.origin));
        merged_links.push(MergedLink {
            name: child_link.name.clone(),
            into: parent,
            origin: j.origin,
            parent: urdf_parent,
            joint_origin,
        });
        // Drop the child link and renumber.
        links.remove(child);
        for k in &mut joints {
            if k.parent > child {
                k.parent -= 1;
            }
            if k.child > child {
                k.child -= 1;
            }
        }
        for m in &mut merged_links {
            if m.into > child {
                m.into -= 1;
            }
        }
    }
    Folded {
        links,
        joints,
        merged,
        merged_links,
        tree_parents,
    }
}
