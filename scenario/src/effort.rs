//! What a run asks of each motor against what it can give: the torque
//! (force, for a prismatic joint) the reference needs along its way,
//! against the joint's effort limit. `testbed robot`, `sim` and `run` say
//! where it comes close, and where there is no limit at all.

use plant_rapier::PlantError;

use crate::{Plan, Prober};

/// A joint whose reference needs more than this fraction of its effort
/// limit is warned about: the controller's own correction has little room.
pub const EFFORT_WARNING_FRACTION: f64 = 0.8;

/// Reference time between the postures checked, s.
const SPACING_S: f64 = 0.05;

/// The warnings for `plan`: joints the reference loads past
/// [`EFFORT_WARNING_FRACTION`] of their effort, and joints without a limit.
pub fn effort_warnings(plan: &Plan) -> Result<Vec<String>, PlantError> {
    let (model, s) = (&plan.robot.model, &plan.scenario);
    if !s.plant.saturate {
        return Ok(Vec::new());
    }
    let n = model.dof();
    let limits: Vec<Option<f64>> = match &s.plant.effort_limit {
        Some(e) => e
            .resolve("plant.effort_limit", n)?
            .into_iter()
            .map(Some)
            .collect(),
        None => model
            .actuated
            .iter()
            .map(|&ji| model.joints[ji].effort)
            .collect(),
    };
    let mut out = Vec::new();
    let unlimited: Vec<&str> = model
        .actuated
        .iter()
        .zip(&limits)
        .filter(|(_, e)| e.is_none())
        .map(|(&ji, _)| model.joints[ji].name.as_str())
        .collect();
    if !unlimited.is_empty() {
        out.push(format!(
            "no effort limit for {} (the URDF gives none, or 0): the plant applies any torque the controller asks; set [plant] effort_limit to a real motor's",
            unlimited.join(", ")
        ));
    }
    let (load, gravity) = loads(plan)?;
    for (i, (&ji, limit)) in model.actuated.iter().zip(&limits).enumerate() {
        let j = &model.joints[ji];
        let unit = j.kind.effort_unit();
        if let Some(e) = limit
            && load[i] > EFFORT_WARNING_FRACTION * e
        {
            out.push(format!(
                "joint '{}': the reference needs up to {:.3} {unit} (gravity up to {:.3}, the rest its motion), {:.0} % of its effort limit {e} {unit}: expect saturation",
                j.name,
                load[i],
                gravity[i],
                100.0 * load[i] / e
            ));
        }
    }
    Ok(out)
}

/// Per joint, along the reference every [`SPACING_S`]: the largest torque
/// it needs, |G(q_d) + M(q_d) q̈_d| plus URDF friction and damping, and the
/// largest gravity torque |G(q_d)|.
fn loads(plan: &Plan) -> Result<(Vec<f64>, Vec<f64>), PlantError> {
    let (model, s) = (&plan.robot.model, &plan.scenario);
    let n = model.dof();
    let armature = s.plant.armature_for(model)?;
    // The run's own gravity: with none, the reference needs no holding torque.
    let mut prober = Prober::with_gravity(model, &armature, s.plant.gravity)?;
    let count = (s.duration_s / SPACING_S).ceil().max(1.0) as usize;
    let (mut load, mut gravity) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..=count {
        let r = plan
            .reference
            .sample(s.duration_s * k as f64 / count as f64);
        let p = prober.at(&r.q_d)?;
        for i in 0..n {
            let j = &model.joints[model.actuated[i]];
            let inertial: f64 = (0..n).map(|c| p.m[(i, c)] * r.qdd_d[c]).sum();
            let urdf = if s.plant.urdf_dynamics {
                j.friction + j.damping * r.qd_d[i].abs()
            } else {
                0.0
            };
            load[i] = f64::max(load[i], (p.gravity[i] + inertial).abs() + urdf);
            gravity[i] = f64::max(gravity[i], p.gravity[i].abs());
        }
    }
    Ok((load, gravity))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's arm with motors of 5 N m, under `gravity`: the note
    /// for joint 1, where the load is mostly gravity.
    fn note(gravity: &str) -> String {
        let plan = crate::load(
            None,
            &crate::Overrides {
                set: vec![
                    crate::parse_set("plant.effort_limit=5").unwrap(),
                    crate::parse_set(&format!("plant.gravity={gravity}")).unwrap(),
                ],
                ..Default::default()
            },
        )
        .unwrap();
        effort_warnings(&plan)
            .unwrap()
            .into_iter()
            .find(|w| w.contains("joint1"))
            .unwrap_or_default()
    }

    /// #50 item 5: the load is the run's own, so a scenario without gravity
    /// counts none.
    #[test]
    fn the_load_counts_the_runs_own_gravity() {
        let with = note("[0.0, 0.0, -9.81]");
        assert!(with.contains("gravity up to"), "{with}");
        assert!(!with.contains("gravity up to 0.000"), "{with}");
        let without = note("[0.0, 0.0, 0.0]");
        assert!(
            without.is_empty() || without.contains("gravity up to 0.000"),
            "{without}"
        );
    }
}
