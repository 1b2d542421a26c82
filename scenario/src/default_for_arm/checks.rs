//! What the default scenario tells a user: loads beyond effort limits,
//! friction no torque overcomes, armature added and why.

use plant_rapier::ArmModel;

use super::types::ArmDefault;
use crate::gains::GainChoice;
use crate::probe::Probe;
use plant_rapier::PlantError;

/// What a joint's armature is for, as `robot` says it.
pub(super) fn armature_purpose(g: &crate::JointGain) -> String {
    match g.armature_for {
        Some(crate::ArmatureFor::Barrier) | None => format!(
            "against the barrier term (K_b Δt/K2 = {:.2} at the widest envelope its range allows)",
            g.barrier
        ),
        Some(crate::ArmatureFor::Load) => format!(
            "within its envelope against its load of {:.3} N m (K1 at most 0.2/Δt)",
            g.load
        ),
    }
}

/// Joints that gravity alone loads beyond their effort limit somewhere
/// along the default reference (a humanoid's 30 N m waist under a 30 kg
/// chest, a mobile base's suspension): no controller holds them, so they
/// are locked where the reference would hold them, and the rest of the arm
/// is controlled. Locks to add, with the reason.
pub(super) fn overloaded(d: &ArmDefault) -> Vec<(String, f64, String)> {
    d.gains
        .joints
        .iter()
        .zip(&d.scenario.reference.joints)
        .filter_map(|(g, r)| {
            let e = g.effort?;
            (g.gravity > e).then(|| {
                (
                    g.name.clone(),
                    r.offset,
                    format!(
                        "gravity alone loads it with up to {:.1} N m along the reference, beyond its effort limit {e} N m: no controller holds it",
                        g.gravity
                    ),
                )
            })
        })
        .collect()
}

/// Joints whose motor cannot bring them from their start into their
/// envelope by T_c, even at full torque (a 1e-9 N m motor, or a wrist
/// whose load takes all of its effort). With `last`, also
/// joints whose load is still at least their effort once the swings are
/// cut (a wrist the other joints' motion loads through the coupling). No
/// controller holds them within the envelope after T_c, so they are
/// locked where the reference holds them. Locks to add, with the reason.
pub(super) fn too_weak(d: &ArmDefault, last: bool) -> Vec<(String, f64, String)> {
    let tc = d.scenario.controller.tc;
    d.gains
        .joints
        .iter()
        .zip(&d.scenario.reference.joints)
        .filter_map(|(g, r)| {
            let effort = g.effort?;
            let why = match g.motor_entry_s {
                Some(t) if t > tc => format!(
                    "its motor (effort {effort} N m, load {:.3} N m) brings it from its start into its envelope in {t:.3} s at best, after T_c = {tc} s: no controller holds it there",
                    g.load
                ),
                _ if last && g.load >= effort => format!(
                    "the reference loads it with {:.3} N m even with its swing cut, at least its effort limit {effort} N m: no controller holds it",
                    g.load
                ),
                _ => return None,
            };
            Some((g.name.clone(), r.offset, why))
        })
        .collect()
}

/// The refusal of an arm whose every joint is [`too_weak`] to control.
pub(super) fn nothing_to_control(weak: &[(String, f64, String)]) -> plant_rapier::PlantError {
    let said: Vec<String> = weak
        .iter()
        .map(|(name, _, why)| format!("'{name}': {why}"))
        .collect();
    plant_rapier::PlantError::InvalidConfig {
        key: "<limit effort> of every controlled joint".into(),
        value: "too weak to control".into(),
        need: format!(
            "enough to move the arm (check the URDF's effort limits); {}",
            said.join("; ")
        ),
    }
}

/// Joints whose URDF dry friction is at least their effort limit (Drake's
/// Allegro hand lists 10 N m of friction on 0.7 N m motors): no motor moves
/// them, so the default turns URDF dynamics off, and says why.
pub(super) fn friction_beyond_effort(model: &ArmModel) -> Option<String> {
    let stuck: Vec<String> = model
        .moving_joints()
        .map(|ji| &model.joints[ji])
        .filter(|j| j.effort.is_some_and(|e| j.friction >= e))
        .map(|j| {
            format!(
                "{} ({} N m ≥ {} N m)",
                j.name,
                j.friction,
                j.effort.unwrap_or(0.0)
            )
        })
        .collect();
    (!stuck.is_empty()).then(|| {
        format!(
            "the URDF's dry friction is at least the effort limit on {}: no motor could move them, so the default turns URDF damping and friction off ([plant] urdf_dynamics = false)",
            stuck.join(", ")
        )
    })
}

/// The share of a joint's effort its reference may need: the rest is the
/// controller's to correct with.
pub(super) const REFERENCE_EFFORT_SHARE: f64 = 0.7;

/// Joints whose reference needs more than [`REFERENCE_EFFORT_SHARE`] of
/// their effort limit: the factor to scale their reference's amplitude by.
/// Where gravity alone leaves room, the motion's load scales with the
/// amplitude, so the factor fits it; where gravity along the swing takes
/// the room (a long arm swung away from upright), the swing is halved,
/// which brings it back towards the posture chosen to unload it.
pub(super) fn within_effort(d: &ArmDefault) -> Vec<(String, f64)> {
    d.gains
        .joints
        .iter()
        .filter_map(|g| {
            let share = REFERENCE_EFFORT_SHARE * g.effort?;
            let (room, motion) = (share - g.gravity, g.load - g.gravity);
            if g.load <= share {
                None
            } else if room > 0.0 {
                Some((g.name.clone(), room / motion))
            } else {
                Some((g.name.clone(), 0.5))
            }
        })
        .collect()
}

/// What `testbed robot` should say about the default scenario beyond its
/// numbers: gravity beyond a motor's effort at the posture the reference
/// swings about, joints no gain holds, envelopes widened.
pub(super) fn warnings(
    model: &ArmModel,
    offsets: &[f64],
    armature: &[f64],
    gains: &GainChoice,
) -> Result<Vec<String>, PlantError> {
    let mut out = Vec::new();
    let probe = Probe::at(model, offsets, armature)?;
    for (i, &ji) in model.actuated.iter().enumerate() {
        let j = &model.joints[ji];
        let g = probe.gravity[i].abs();
        if let Some(e) = j.effort
            && g > e
        {
            out.push(format!(
                "joint '{}': gravity alone loads it with {g:.1} N m at the default posture, beyond its effort limit {e} N m: it cannot hold the arm up and every step will saturate (check the URDF's masses and effort limits, or set [plant] effort_limit)",
                j.name
            ));
        }
    }
    for j in &gains.joints {
        if let Some(a) = j.armature_needed {
            out.push(format!(
                "joint '{}': no gain holds it at {} Hz {} even with the armature added (it needs {a:.2e} more); lock it in [plant.lock] or raise rate_hz",
                j.name,
                gains.rate_hz,
                armature_purpose(j)
            ));
        }
        if let Some(why) = &j.envelope_reason {
            out.push(format!("joint '{}': envelope widened for {why}", j.name));
        }
    }
    Ok(out)
}
