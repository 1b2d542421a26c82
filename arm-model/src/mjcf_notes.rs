//! What an MJCF model says that the testbed names and does not apply:
//! the model's own gravity, `gravcomp`, equality constraints and tendons,
//! joint springs. `mjcf.rs` adds these notes to the model it reads.

use mjcf_rs::body::{Body, Joint};
use nalgebra::Vector3;

use super::mjcf_include::{attribute, tags};

/// `<body name>`, or its index when unnamed: how notes and errors name a
/// body (and the link it becomes).
pub(crate) fn body_name(b: &Body, id: usize) -> String {
    b.name.clone().unwrap_or_else(|| format!("body{id}"))
}

/// The model-wide notes, in the order a reader meets them.
pub(crate) fn unapplied(m: &mjcf_rs::Model, whole: &str) -> Vec<String> {
    [gravity(m, whole), gravcomp(m), coupling(m)]
        .into_iter()
        .flatten()
        .collect()
}

/// Gravity is the scenario's (`[plant] gravity`), as every other part of
/// an experiment: a model's own (its `<option gravity>`, or gravity turned
/// off by `<flag gravity="disable">`) is named so that a user can set it.
fn gravity(m: &mjcf_rs::Model, whole: &str) -> Option<String> {
    let off = tags(whole, "flag").any(|t| attribute(t, "gravity") == Some("disable"));
    if off {
        return Some(
            "MJCF <flag gravity=\"disable\"> is not applied: gravity is the scenario's (plant.gravity, default [0, 0, -9.81]); set plant.gravity = [0, 0, 0] to run with the model's".into(),
        );
    }
    let g = m.option.gravity;
    (Vector3::from(g) != crate::dynamics::GRAVITY).then(|| {
        format!(
            "MJCF <option gravity=\"{} {} {}\"> is not applied: gravity is the scenario's (plant.gravity, default [0, 0, -9.81]); set plant.gravity = [{}, {}, {}] to run with the model's",
            g[0], g[1], g[2], g[0], g[1], g[2]
        )
    })
}

/// MuJoCo's `gravcomp` is a passive force that cancels gravity on a body,
/// standing in for a position-controlled arm's own compensation; here the
/// controller under test meets gravity, so it is named and not applied.
fn gravcomp(m: &mjcf_rs::Model) -> Option<String> {
    let bodies: Vec<String> = (m.bodies.iter().enumerate())
        .filter(|(_, e)| e.body.gravcomp != 0.0)
        .map(|(id, e)| body_name(&e.body, id))
        .collect();
    (!bodies.is_empty()).then(|| {
        format!(
            "MJCF gravcomp on {} bod{} ({}) is not applied: gravity loads the arm and the controller under test meets it",
            bodies.len(),
            if bodies.len() == 1 { "y" } else { "ies" },
            bodies.join(", ")
        )
    })
}

/// Equality constraints and tendons tie joints together (a gripper's
/// closed linkage); the plant moves the tree as an open chain.
fn coupling(m: &mjcf_rs::Model) -> Option<String> {
    use mjcf_rs::equality::Equality;
    let count = |f: fn(&Equality) -> bool| m.equality.iter().filter(|e| f(e)).count();
    let kinds = [
        ("connect", count(|e| matches!(e, Equality::Connect(_)))),
        ("weld", count(|e| matches!(e, Equality::Weld(_)))),
        ("joint", count(|e| matches!(e, Equality::Joint(_)))),
        ("tendon", count(|e| matches!(e, Equality::Tendon(_)))),
    ];
    let mut parts: Vec<String> = (kinds.iter())
        .filter(|(_, n)| *n > 0)
        .map(|(k, n)| format!("{n} <equality><{k}>"))
        .collect();
    if !m.tendons.is_empty() {
        parts.push(format!("{} <tendon>", m.tendons.len()));
    }
    (!parts.is_empty()).then(|| {
        format!(
            "MJCF {} not simulated: the joints they couple move freely (lock them with [plant] lock, as the default scenario locks a gripper's fingers)",
            parts.join(", ")
        )
    })
}

/// What an MJCF joint has that the testbed does not simulate.
pub(crate) fn joint(j: &Joint, element: &str) -> Vec<String> {
    let mut notes = Vec::new();
    if j.stiffness != 0.0 {
        notes.push(format!(
            "{element}: stiffness {} (spring to springref {}) is not simulated",
            j.stiffness, j.springref
        ));
    }
    if j.springdamper.is_some() {
        notes.push(format!("{element}: springdamper is not simulated"));
    }
    notes
}
