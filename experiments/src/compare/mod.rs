//! `testbed compare`: every law on the same scenario and seeds, in process,
//! on every core, scored on BASELINES.md's metrics.
//!
//! Each run is exactly `testbed sim --law L` with the scenario's seed + s:
//! the same plan ([`plan_for`]), the same loop ([`run_stack::sim`]), the same
//! summary, so a row can be checked against a single run bit for bit.

use analysis::law_info::LawInfo;
use rayon::prelude::*;
use scenario::Plan;

pub mod external;
pub mod findings;
mod paired;
pub mod plots;
pub mod ratio_plot;
pub mod runs;
pub mod scores;
pub mod tradeoff;
pub mod types;

use external::external_row;
pub use runs::{plan_for, random_effects, run_one, run_until};
pub use scores::{METRICS, Metric, PAIRED_METRICS, failed_because, holm, scored, stats_of};
use scores::{paired, row};
pub use types::*;

/// Runs every law on every seed and scores them.
pub fn compare(plan: &Plan, opts: &CompareOptions) -> Result<Comparison, CompareError> {
    if (opts.laws.is_empty() && opts.external.is_empty()) || opts.seeds == 0 {
        return Err(CompareError::Empty(
            "compare needs at least one law and one seed",
        ));
    }
    for (k, law) in opts.laws.iter().enumerate() {
        if opts.laws[..k].contains(law) {
            return Err(CompareError::DuplicateLaw(*law));
        }
    }
    let mut jobs = Vec::new();
    for &law in &opts.laws {
        for s in 0..opts.seeds {
            jobs.push((law, s, plan_for(plan, law, s, opts.tuning, &opts.law_sets)?));
        }
    }
    let threads = opts
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| CompareError::Threads {
            threads,
            cause: e.to_string(),
        })?;
    let start = std::time::Instant::now();
    let total = jobs.len() + opts.external.len() * opts.seeds as usize;
    let bar = crate::progress::bar(opts.progress, total);
    let runs: Vec<LawRun> = pool.install(|| {
        jobs.par_iter()
            .map(|(_, s, p)| {
                let r = run_one(p, opts.series && *s == 0);
                if let Some(b) = &bar {
                    b.inc(1);
                }
                r
            })
            .collect()
    });
    let mut runs = runs.into_iter();
    let laws = opts
        .laws
        .iter()
        .map(|&law| {
            let mine: Vec<LawRun> = runs.by_ref().take(opts.seeds as usize).collect();
            let info = jobs
                .iter()
                .find(|(l, _, _)| *l == law)
                .map(|(_, _, p)| LawInfo::of(&p.scenario.controller));
            row(
                info.unwrap_or_else(|| LawInfo::of(&plan.scenario.controller.for_law(law))),
                mine,
            )
        })
        .collect::<Vec<_>>();
    let mut laws = laws;
    for spec in &opts.external {
        laws.push(external_row(plan, spec, opts, bar.as_ref())?);
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let wall_time_s = start.elapsed().as_secs_f64();
    let random = random_effects(plan);
    let mut warnings = Vec::new();
    let identical = opts.seeds > 1 && crate::compare::scores::identical_seeds(&laws);
    if identical {
        warnings.push(format!(
            "the {} seeds gave identical runs (the scenario has nothing random): they are one run, and no paired test is made",
            opts.seeds
        ));
    }
    if opts.seeds == 1 && !random.is_empty() {
        warnings.push(format!(
            "one seed of random effects ({}): one draw, so no difference between laws is reported (use --seeds 5 or more)",
            random.join(", ")
        ));
    }
    let paired = if identical { Vec::new() } else { paired(&laws) };
    let mut c = Comparison {
        scenario: plan.scenario.name.clone(),
        scenario_source: plan.source.clone(),
        robot: plan.robot.label(),
        duration_s: plan.steps as f64 * plan.dt(),
        seeds: opts.seeds,
        threads,
        wall_time_s,
        laws,
        paired,
        findings: Vec::new(),
        warnings,
        random_effects: random,
        tuning: opts.tuning.unwrap_or(plan.scenario.controller.tuning),
    };
    c.findings = crate::compare::findings::findings(&c);
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use controller::LawName;

    #[test]
    fn a_law_twice_is_an_error() {
        let plan = scenario::load(None, &scenario::Overrides::default()).unwrap();
        let opts = CompareOptions {
            law_sets: Vec::new(),
            external: Vec::new(),
            runs_dir: std::path::PathBuf::from("runs"),
            progress: false,
            laws: vec![LawName::Pd, LawName::Nac, LawName::Pd],
            seeds: 1,
            threads: Some(1),
            series: false,
            tuning: None,
        };
        let err = compare(&plan, &opts).unwrap_err();
        assert!(
            matches!(err, CompareError::DuplicateLaw(LawName::Pd)),
            "{err}"
        );
    }

    #[test]
    fn no_law_is_an_error() {
        let plan = scenario::load(None, &scenario::Overrides::default()).unwrap();
        let opts = CompareOptions {
            law_sets: Vec::new(),
            external: Vec::new(),
            runs_dir: std::path::PathBuf::from("runs"),
            progress: false,
            laws: vec![],
            seeds: 1,
            threads: Some(1),
            series: false,
            tuning: None,
        };
        assert!(compare(&plan, &opts).is_err());
    }
}
