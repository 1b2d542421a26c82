//! One run of a comparison, exactly as `testbed sim --law L` makes it.

use std::sync::atomic::{AtomicBool, Ordering};

use analysis::summary::SummaryBuilder;
use run_stack::sim::{self, StepCosts};
use scenario::Plan;

use crate::compare::scores::scored;
use crate::compare::types::{CompareError, LawRun, LawSeries, LawSet};
use controller::{ControllerParams, LawName, Tuning};

/// The plan of `testbed sim --law <law>` with seed `plan.seed + s`: the
/// scenario before its draws, for `law`, with that seed's `[randomise]`
/// draws (the same for every law).
pub fn plan_for(
    plan: &Plan,
    law: LawName,
    s: u64,
    tuning: Option<Tuning>,
    law_sets: &[LawSet],
) -> Result<Plan, CompareError> {
    let mut scenario = plan.undrawn.clone();
    scenario.controller = scenario.controller.for_law(law);
    for set in law_sets.iter().filter(|x| x.law == law) {
        scenario.controller = with_key(&scenario.controller, set)?;
    }
    if let Some(t) = tuning.filter(|_| law.takes("tuning")) {
        scenario.controller.tuning = t;
    }
    scenario.seed = plan.undrawn.seed.wrapping_add(s);
    let seed = scenario.seed;
    let fail = |cause| CompareError::Plan { law, seed, cause };
    scenario.validate(&plan.source).map_err(fail)?;
    scenario::plan(
        scenario,
        plan.source.clone(),
        plan.toml.clone(),
        plan.robot.clone(),
    )
    .map_err(fail)
}

/// `params` with one of its keys set as the scenario file would set it.
fn with_key(params: &ControllerParams, set: &LawSet) -> Result<ControllerParams, CompareError> {
    let fail = |cause| CompareError::LawSet {
        law: set.law,
        key: set.key.clone(),
        cause,
    };
    let mut table =
        toml::Table::try_from(params).map_err(|e| fail(serde::de::Error::custom(e.to_string())))?;
    table.insert(set.key.clone(), set.value.clone());
    table.try_into().map_err(fail)
}

/// What a seed changes in `plan` besides nothing: its `[randomise]` table
/// and the plant's random effects (noise, lost commands).
pub fn random_effects(plan: &Plan) -> Vec<String> {
    let s = &plan.undrawn;
    let p = &s.plant;
    [
        (!s.randomise.is_empty(), "a [randomise] table"),
        (
            !(p.sensor.q_noise_std.is_zero() && p.sensor.qd_noise_std.is_zero()),
            "sensor noise",
        ),
        (!p.disturbance.noise_std.is_zero(), "disturbance noise"),
        (p.actuation.drop_probability > 0.0, "dropped commands"),
    ]
    .into_iter()
    .filter(|(on, _)| *on)
    .map(|(_, what)| what.to_string())
    .collect()
}

/// One in-process run, exactly as `testbed sim` makes it.
pub fn run_one(plan: &Plan, keep_series: bool) -> LawRun {
    run_inner(plan, keep_series, &AtomicBool::new(false)).0
}

/// [`run_one`] without curves, given up (None) once `stop` is set.
pub fn run_until(plan: &Plan, stop: &AtomicBool) -> Option<LawRun> {
    let (run, stopped) = run_inner(plan, false, stop);
    (!stopped).then_some(run)
}

/// The run, and whether `stop` cut it short.
fn run_inner(plan: &Plan, keep_series: bool, stop: &AtomicBool) -> (LawRun, bool) {
    let names = plan.robot.model.joint_names();
    let n = names.len();
    let mut summary = SummaryBuilder::new(names, plan.dt(), plan.scenario.controller.tc)
        .with_gravity(&plan.robot.model);
    let mut series = keep_series.then(|| LawSeries {
        e: vec![Vec::new(); n],
        kc: vec![Vec::new(); n],
        ..LawSeries::default()
    });
    let mut costs = StepCosts::default();
    let result = sim::run_measured(plan, Some(&mut costs), |r| {
        if stop.load(Ordering::Relaxed) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Interrupted,
                "stopped",
            ));
        }
        summary.add(r);
        if let Some(s) = series.as_mut() {
            s.t.push(r.t);
            for i in 0..n {
                s.e[i].push(r.q[i] - r.q_d[i]);
                s.kc[i].push(r.kc[i]);
            }
        }
        Ok(())
    });
    let failure = result.err().map(|e| e.to_string());
    let run = scored(
        plan.scenario.seed,
        failure,
        summary.finish(),
        costs.controller_us.finish(),
        series,
    );
    (run, stop.load(Ordering::Relaxed))
}
