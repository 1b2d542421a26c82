//! An MJCF model's home pose: its keyframe `home` (else the first), the
//! start of the arm's default scenario.
//!
//! A key's `qpos` of 100 on a joint of range ±1 (or `inf`) was taken as
//! given, then clamped into the limits by the default scenario and shown
//! as "the model's home pose … inside the limits" (#60 item 9): a value
//! that is not finite, or outside the joint's range, is refused by name.

use std::collections::HashMap;

use super::ArmModel;
use crate::ModelError;

/// How far outside its joint's range a key's value may lie, as a share
/// of the range: the rounding of a value written at a limit (1.5708 for
/// a range of ±90°), not a pose outside it.
const RANGE_ROUNDING: f64 = 1e-4;

/// The keyframe named `home` (else the first) as a pose of the controlled
/// joints; None when the file has no key.
pub(crate) fn home(
    m: &mjcf_rs::Model,
    model: &ArmModel,
    qpos_order: &[String],
) -> Result<Option<Vec<f64>>, ModelError> {
    let Some(key) = (m.keyframes.iter())
        .find(|k| k.name.as_deref() == Some("home"))
        .or_else(|| m.keyframes.first())
    else {
        return Ok(None);
    };
    let label = key.name.clone().unwrap_or_else(|| "#0".into());
    let refuse = |reason: String| ModelError::MjcfRefused {
        element: format!("<key name='{label}'>"),
        reason,
    };
    if key.qpos.is_empty() {
        return Ok(None);
    }
    if key.qpos.len() != qpos_order.len() {
        return Err(refuse(format!(
            "qpos has {} values for {} joints",
            key.qpos.len(),
            qpos_order.len()
        )));
    }
    let by_name: HashMap<&str, f64> = qpos_order
        .iter()
        .map(String::as_str)
        .zip(key.qpos.iter().copied())
        .collect();
    if let Some((joint, q)) = (qpos_order.iter().zip(&key.qpos)).find(|(_, q)| !q.is_finite()) {
        return Err(refuse(format!(
            "qpos gives joint '{joint}' the value {q}, not a finite number (in radians or metres)"
        )));
    }
    let pose: Vec<f64> = (model.joint_names().iter())
        .map(|n| by_name.get(n.as_str()).copied().unwrap_or(0.0))
        .collect();
    outside_range(model, &pose).map_or(Ok(Some(pose)), |reason| Err(refuse(reason)))
}

/// Why the pose of the controlled joints is no home pose, if it lies
/// outside a joint's range (beyond the rounding of a value at a limit).
fn outside_range(model: &ArmModel, pose: &[f64]) -> Option<String> {
    model.actuated.iter().zip(pose).find_map(|(&ji, &q)| {
        let j = &model.joints[ji];
        let (lo, hi) = j.limits?;
        let slack = RANGE_ROUNDING * (hi - lo);
        let unit = match j.kind {
            super::JointKind::Prismatic => "m",
            _ => "rad",
        };
        let n = super::mjcf_actuators::number;
        (q < lo - slack || q > hi + slack).then(|| {
            format!(
                "qpos puts joint '{}' at {} {unit}, outside its range [{}, {}] {unit}: a home pose lies inside the joint's limits (correct the key, or remove it to have the start chosen as for a URDF)",
                j.name,
                n(q),
                n(lo),
                n(hi)
            )
        })
    })
}
