//! What a contact scenario must be before anything runs: objects grasped by
//! links that move, a robot with primitives to collide and none that are
//! broken, and obstacles clear of the arm at its first state (an obstacle
//! through a link or a joint axis is met with a correction the solver
//! cannot make, and the arm blows up on the first step).

use arm_model::ArmModel;
use arm_model::dynamics::Dynamics;
use rapier3d_f64::parry::query;
use rapier3d_f64::prelude::*;

use super::shapes::{pose, shape};
use crate::{ContactConfig, PlantError};

/// What the engine itself checks when it builds the colliders (the rest
/// needs the initial state).
pub(super) fn check_contact_shapes(
    model: &ArmModel,
    contact: &ContactConfig,
) -> Result<(), PlantError> {
    grasping_links(model, contact)?;
    usable_shapes(model)
}

/// Checks `contact` for `model` with the arm at `q0` (one entry per
/// controlled joint); errors name the key.
pub fn check_contact(
    model: &ArmModel,
    contact: &ContactConfig,
    q0: &[f64],
) -> Result<(), PlantError> {
    if contact.is_off() {
        return Ok(());
    }
    grasping_links(model, contact)?;
    usable_shapes(model)?;
    clear_at_start(model, contact, q0)
}

fn invalid(key: String, value: impl ToString, need: impl ToString) -> PlantError {
    PlantError::InvalidConfig {
        key,
        value: value.to_string(),
        need: need.to_string(),
    }
}

/// Each object's link exists and moves (the root, and links folded into
/// it, never do).
fn grasping_links(model: &ArmModel, contact: &ContactConfig) -> Result<(), PlantError> {
    for (i, o) in contact.object.iter().enumerate() {
        let key = format!("plant.contact.object[{i}].link");
        let moving = || {
            model
                .links
                .iter()
                .enumerate()
                .filter(|(l, _)| *l != model.root)
                .map(|(_, l)| l.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        match model.locate_link(&o.link) {
            Some((l, _)) if l != model.root => {}
            Some(_) => {
                return Err(invalid(
                    key,
                    format!("\"{}\"", o.link),
                    format!("a link that moves, not the fixed base ({})", moving()),
                ));
            }
            None => {
                return Err(invalid(
                    key,
                    format!("\"{}\"", o.link),
                    format!("one of the robot's moving links ({})", moving()),
                ));
            }
        }
    }
    Ok(())
}

/// Some link has a primitive, and no primitive is broken.
fn usable_shapes(model: &ArmModel) -> Result<(), PlantError> {
    if let Some(bad) = model.links.iter().flat_map(|l| &l.bad_collisions).next() {
        return Err(invalid(
            "plant.contact".into(),
            "set",
            format!("a URDF whose <collision> primitives are all sound: {bad}"),
        ));
    }
    if model.links.iter().all(|l| l.collisions.is_empty()) {
        let meshes: Vec<&str> = model
            .links
            .iter()
            .flat_map(|l| l.skipped_collisions.iter().map(String::as_str))
            .take(3)
            .collect();
        let need = "links with <collision> primitives (box, cylinder, sphere, capsule): this robot has none";
        return Err(invalid(
            "plant.contact".into(),
            "set",
            match meshes.is_empty() {
                true => need.to_string(),
                false => format!(
                    "{need} (meshes are not contact shapes: {}, …)",
                    meshes.join("; ")
                ),
            },
        ));
    }
    Ok(())
}

/// No obstacle or free object overlaps a link's primitive with the arm
/// at `q0`.
fn clear_at_start(model: &ArmModel, contact: &ContactConfig, q0: &[f64]) -> Result<(), PlantError> {
    let mut dynamics = Dynamics::new(model, 1.0);
    let links: Vec<Pose> = dynamics
        .link_poses(q0)
        .iter()
        .map(|p| {
            let (t, r) = (p.translation.vector, p.rotation);
            Pose::from_parts(
                Vector::new(t.x, t.y, t.z),
                Rotation::from_xyzw(r.i, r.j, r.k, r.w),
            )
        })
        .collect();
    // Obstacles and free objects alike: the arm must start clear of both.
    let mut bodies = Vec::new();
    for (i, o) in contact.obstacle.iter().enumerate() {
        let key = format!("plant.contact.obstacle[{i}]");
        bodies.push((
            key,
            format!("\"{}\"", o.label(i)),
            o.origin(),
            o.geometry(i)?,
        ));
    }
    // An object grasped from the first step is part of its link at once.
    for (i, o) in contact
        .object
        .iter()
        .enumerate()
        .filter(|(_, o)| o.grasp_at_s > 0.0)
    {
        let key = format!("plant.contact.object[{i}]");
        bodies.push((key, format!("object {}", i + 1), o.origin(), o.geometry(i)?));
    }
    for (key, label, origin, geometry) in bodies {
        let (at, body) = (pose(&origin), shape(&geometry).shape);
        for (link, p) in model.links.iter().zip(&links) {
            for c in &link.collisions {
                let (cp, cs) = (*p * pose(&c.origin), shape(&c.geometry).shape);
                let hit =
                    query::intersection_test(&at, &*body, &cp, &*cs).is_ok_and(|x| x.intersecting);
                if hit {
                    return Err(invalid(
                        key,
                        label,
                        format!(
                            "clear of the arm where it starts: it overlaps link '{}' at the initial q",
                            link.name
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}
