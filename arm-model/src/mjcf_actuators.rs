//! An MJCF model's actuators as the testbed reads them: effort limits
//! (a motor's gear × its control range, any actuator's force range), and
//! what is not used, named (servo gains, actuators on tendons or sites).

use mjcf_rs::extras::ActuatorKind;

use super::{ArmModel, JointKind};

/// Effort limits from the actuators that drive a joint (a motor's gear ×
/// its control range, any actuator's force range; the joint's own
/// `actuatorfrcrange` is applied by the caller), and notes on what is
/// not used: servo gains (the controller is the testbed's own) and
/// actuators on tendons or sites.
pub(crate) fn actuators(m: &mjcf_rs::Model, model: &mut ArmModel) -> Vec<String> {
    let mut notes = Vec::new();
    let auto = m.compiler.autolimits;
    for (i, a) in m.actuators.iter().enumerate() {
        let label = a.name.clone().unwrap_or_else(|| format!("#{i}"));
        let Some(joint) = &a.joint else {
            notes.push(format!(
                "actuator '{label}' drives no joint (a tendon, site or body): ignored"
            ));
            continue;
        };
        let bound = |r: Option<[f64; 2]>, limited: mjcf_rs::types::Tristate| {
            r.filter(|_| limited.resolve(auto, r.is_some()))
                .map(|r| r[0].abs().max(r[1].abs()))
        };
        // forcerange clamps the actuator's force; the joint feels gear × it.
        let force = bound(a.force_range, a.force_limited).map(|f| f * a.gear[0].abs());
        let ctrl = match a.kind {
            ActuatorKind::Motor => bound(a.ctrl_range, a.ctrl_limited).map(|c| c * a.gear[0].abs()),
            _ => {
                notes.push(format!(
                    "actuator '{label}' is a {:?} servo on '{joint}': its gains are ignored (the controller is the testbed's own)",
                    a.kind
                ));
                None
            }
        };
        let effort = match (force, ctrl) {
            (Some(f), Some(c)) => Some(f.min(c)),
            (f, c) => f.or(c),
        };
        let target = model
            .joints
            .iter_mut()
            .find(|j| &j.name == joint && j.kind != JointKind::Fixed);
        if let (Some(j), Some(e)) = (target, effort.filter(|e| *e > 0.0)) {
            j.effort = Some(j.effort.map_or(e, |old| old.min(e)));
        }
    }
    notes
}
