//! An MJCF model's actuators as the testbed reads them: effort limits
//! (a motor's gear × its control range, any actuator's force range), and
//! what is not used, named (servo gains, actuators on tendons or sites).
//!
//! A limit that is zero or not a number used to become "no limit" (the
//! plant then applies any torque) and one of 1e308 passed as a real one
//! (#60 item 9): both are refused, naming the actuator and the attribute.

use mjcf_rs::extras::{Actuator, ActuatorKind};

use super::{ArmModel, JointKind};
use crate::ModelError;

/// The largest effort limit an MJCF actuator or joint may give, N m or N:
/// a large industrial arm's base joint takes about 10⁴ N m; beyond 10⁶ the
/// number is a stand-in for "unlimited", which the model should say by
/// leaving the range out.
pub const MAX_MJCF_EFFORT: f64 = 1e6;

/// Effort limits from the actuators that drive a joint (a motor's gear ×
/// its control range, any actuator's force range; the joint's own
/// `actuatorfrcrange` is applied by the caller), and notes on what is
/// not used: servo gains (the controller is the testbed's own) and
/// actuators on tendons or sites.
pub(crate) fn actuators(
    m: &mjcf_rs::Model,
    model: &mut ArmModel,
) -> Result<Vec<String>, ModelError> {
    let mut notes = Vec::new();
    for (i, a) in m.actuators.iter().enumerate() {
        let label = a.name.clone().unwrap_or_else(|| format!("#{i}"));
        let Some(joint) = &a.joint else {
            notes.push(format!(
                "actuator '{label}' drives no joint (a tendon, site or body): ignored"
            ));
            continue;
        };
        if a.kind != ActuatorKind::Motor {
            notes.push(format!(
                "actuator '{label}' is a {:?} servo on '{joint}': its gains are ignored (the controller is the testbed's own)",
                a.kind
            ));
        }
        let element = format!(
            "<{} name='{label}'> on joint '{joint}'",
            format!("{:?}", a.kind).to_lowercase()
        );
        let Some(effort) = effort(m.compiler.autolimits, a, &element)? else {
            continue;
        };
        let target = model
            .joints
            .iter_mut()
            .find(|j| &j.name == joint && j.kind != JointKind::Fixed);
        if let Some(j) = target {
            j.effort = Some(j.effort.map_or(effort, |old| old.min(effort)));
        }
    }
    Ok(notes)
}

/// The effort limit one actuator puts on its joint, if any: gear × its
/// force bound, gear × its control bound for a motor (the smaller).
fn effort(auto: bool, a: &Actuator, element: &str) -> Result<Option<f64>, ModelError> {
    let gear = a.gear[0];
    if !gear.is_finite() || gear == 0.0 {
        return Err(refuse(
            element,
            format!(
                "gear {} is not a finite, non-zero number (the actuator would push its joint with no force, or with none that is a number)",
                number(gear)
            ),
        ));
    }
    let bound = |r: Option<[f64; 2]>, limited: mjcf_rs::types::Tristate| {
        r.filter(|_| limited.resolve(auto, r.is_some()))
    };
    // forcerange clamps the actuator's force; the joint feels gear × it.
    let force = bound(a.force_range, a.force_limited)
        .map(|r| checked(element, "forcerange", r, gear))
        .transpose()?;
    let ctrl = match a.kind {
        ActuatorKind::Motor => bound(a.ctrl_range, a.ctrl_limited)
            .map(|r| checked(element, "ctrlrange", r, gear))
            .transpose()?,
        _ => None,
    };
    Ok(match (force, ctrl) {
        (Some(f), Some(c)) => Some(f.min(c)),
        (f, c) => f.or(c),
    })
}

/// gear × the larger end of `range`, refused unless it is a usable limit.
fn checked(element: &str, attribute: &str, range: [f64; 2], gear: f64) -> Result<f64, ModelError> {
    let limit = range[0].abs().max(range[1].abs()) * gear.abs();
    let what = format!(
        "{attribute} \"{} {}\" × gear {}",
        number(range[0]),
        number(range[1]),
        number(gear)
    );
    usable_limit(limit, &what).map_err(|reason| refuse(element, reason))
}

/// `limit` when it is a usable effort limit; else why not. Shared with
/// the joint's own `actuatorfrcrange`.
pub(crate) fn usable_limit(limit: f64, what: &str) -> Result<f64, String> {
    if !limit.is_finite() {
        return Err(format!(
            "{what} is an effort limit of {limit}, not a finite number"
        ));
    }
    if limit == 0.0 {
        return Err(format!(
            "{what} is an effort limit of 0: the joint could not be driven (leave the range out, or set ctrllimited/forcelimited=\"false\", for no limit)"
        ));
    }
    if limit > MAX_MJCF_EFFORT {
        return Err(format!(
            "{what} is an effort limit of {limit:e}, above {MAX_MJCF_EFFORT:e} (N m or N), more than any arm's motor: leave the range out for no limit"
        ));
    }
    Ok(limit)
}

/// A number as a message shows it: 1e300 as such, not its 301 digits.
pub(crate) fn number(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

fn refuse(element: &str, reason: String) -> ModelError {
    ModelError::MjcfRefused {
        element: element.to_string(),
        reason,
    }
}
