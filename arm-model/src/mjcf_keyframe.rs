//! An MJCF model's home pose: its keyframe `home` (else the first), the
//! start of the arm's default scenario.

use std::collections::HashMap;

use super::ArmModel;
use crate::ModelError;

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
    if key.qpos.is_empty() {
        return Ok(None);
    }
    if key.qpos.len() != qpos_order.len() {
        return Err(ModelError::MjcfRefused {
            element: format!("<key name='{label}'>"),
            reason: format!(
                "qpos has {} values for {} joints",
                key.qpos.len(),
                qpos_order.len()
            ),
        });
    }
    let by_name: HashMap<&str, f64> = qpos_order
        .iter()
        .map(String::as_str)
        .zip(key.qpos.iter().copied())
        .collect();
    Ok(Some(
        model
            .joint_names()
            .iter()
            .map(|n| by_name.get(n.as_str()).copied().unwrap_or(0.0))
            .collect(),
    ))
}
