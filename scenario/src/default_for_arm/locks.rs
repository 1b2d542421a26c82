//! Which joints the default scenario locks: grippers and fingers, and
//! joints that move no mass.

use plant_rapier::ArmModel;

/// Why a gripper or finger joint is locked (the start of its reason).
pub const GRIPPER_LOCK: &str = "a gripper or finger joint: the controller drives the arm";

/// Joint names that mark a gripper or a finger (compared in lower case).
const GRIPPER_WORDS: [&str; 6] = ["finger", "gripper", "grip", "hand", "jaw", "claw"];

/// Whether a joint's name says it belongs to a gripper or a hand.
fn is_gripper(name: &str) -> bool {
    let lower = name.to_lowercase();
    GRIPPER_WORDS.iter().any(|w| lower.contains(w))
}

/// Where a locked joint is held: the middle of its range, or 0.
pub(super) fn lock_position(limits: Option<(f64, f64)>) -> f64 {
    limits.map_or(0.0, |(lo, hi)| 0.5 * (lo + hi))
}

/// The joints the default scenario locks: grippers and fingers, and joints
/// that move no mass, as long as some joint is left to control.
pub(super) fn default_locks(full: &ArmModel) -> Vec<(String, f64, String)> {
    let massless = full.joints_moving_no_mass();
    let mut locks: Vec<(String, f64, String)> = Vec::new();
    for &ji in &full.actuated {
        let j = &full.joints[ji];
        let why = if is_gripper(&j.name) {
            GRIPPER_LOCK
        } else if massless.contains(&j.name) {
            "it moves no mass, so its acceleration is undefined"
        } else {
            continue;
        };
        locks.push((j.name.clone(), lock_position(j.limits), why.to_string()));
    }
    if locks.len() == full.dof() {
        // Nothing would be left to control: lock nothing, and let the plant
        // say what it cannot simulate.
        locks.clear();
    }
    locks
}
