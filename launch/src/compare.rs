//! `testbed compare`: every law on the same scenario and seeds, in process,
//! on every core, scored on BASELINES.md's metrics.
//!
//! Each run is exactly `testbed sim --law L` with the scenario's seed + s:
//! the same plan ([`plan_for`]), the same loop ([`crate::sim`]), the same
//! summary, so a row can be checked against a single run bit for bit.

use std::sync::atomic::{AtomicBool, Ordering};

use controller::{LawName, Tuning};
use rayon::prelude::*;
use scenario::Plan;
use serde::Serialize;

use crate::compare_external::external_row;
pub use crate::compare_external::{ExternalRow, ExternalSpec};
use crate::compare_scores::paired;
pub(crate) use crate::compare_scores::row;
pub use crate::compare_scores::{
    Envelope, METRICS, Metric, PAIRED_METRICS, Stats, failed_because, holm, scored, stats_of,
};
use crate::sim::{self, StepCosts};
use analysis::law_info::LawInfo;
use analysis::stats::{MedianInterval, SignedRank};
use analysis::summary::{Summary, SummaryBuilder};
use analysis::timing::Percentiles;

/// The laws `compare` runs when none are named: the paper's law, its
/// ablations, the classic barrier law, PD, computed torque, PPC, sliding
/// mode, computed torque through a CBF filter and the constrained MPC.
pub const DEFAULT_LAWS: [LawName; 11] = [
    LawName::Nac,
    LawName::NacNoShift,
    LawName::NacNoCritic,
    LawName::NacNoNetworks,
    LawName::Blf,
    LawName::Pd,
    LawName::Ctc,
    LawName::Ppc,
    LawName::Smc,
    LawName::CbfCtc,
    LawName::Mpc,
];

/// The most seeds per law `compare` runs: each run's summary is kept, and a
/// table of medians and intervals needs far fewer; a larger study is a
/// sweep, which streams its results.
pub const MAX_SEEDS: u64 = 10_000;

/// Why a comparison could not be made.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// A law or seed turns the scenario into an invalid one.
    #[error("{law}, seed {seed}: {cause}")]
    Plan {
        /// The law.
        law: LawName,
        /// The seed.
        seed: u64,
        /// The cause.
        cause: scenario::ScenarioError,
    },
    /// The worker threads could not be started.
    #[error("cannot start {threads} worker threads: {cause}")]
    Threads {
        /// Threads asked for.
        threads: usize,
        /// The cause.
        cause: String,
    },
    /// Nothing to run.
    #[error("{0}")]
    Empty(&'static str),
}

/// What to run.
#[derive(Debug, Clone)]
pub struct CompareOptions {
    /// The laws, in table order.
    pub laws: Vec<LawName>,
    /// Seeds per law: the scenario's seed, +1, … (at least 1).
    pub seeds: u64,
    /// Worker threads (None: one per CPU).
    pub threads: Option<usize>,
    /// Keep the first seed's error, envelope and torque per law, for figures.
    pub series: bool,
    /// The tuning rule of the laws that take one (None: the scenario's).
    pub tuning: Option<Tuning>,
    /// Users' controllers, scored beside the built-in laws: each seed runs
    /// through the lockstep stack with the command as the controller node.
    pub external: Vec<ExternalSpec>,
    /// Where the external controllers' run folders go.
    pub runs_dir: std::path::PathBuf,
    /// Show a progress bar on standard error (a terminal).
    pub progress: bool,
}

/// The first seed's curves of one law, for the overlay figures.
#[derive(Debug, Clone, Default)]
pub struct LawSeries {
    /// Sim time, s.
    pub t: Vec<f64>,
    /// e = q − q_d per joint (the true state).
    pub e: Vec<Vec<f64>>,
    /// k_c per joint.
    pub kc: Vec<Vec<f64>>,
}

/// One run of one law.
#[derive(Debug, Clone, Serialize)]
pub struct LawRun {
    /// The seed of every random effect.
    pub seed: u64,
    /// Why the run stopped early, if it did (the summary covers the steps before).
    pub failure: Option<String>,
    /// Why the run failed, if it did ([`failed_because`]: it could not be
    /// scored): a failed run's metrics count as the worst, whatever their
    /// values.
    pub failed: Option<String>,
    /// Whether it kept |e| < k_c after T_c, left it, or ended before T_c.
    pub envelope: Envelope,
    /// The run's summary, as `testbed sim --law` prints it.
    pub summary: Summary,
    /// Controller compute per step, µs.
    pub compute_us: Percentiles,
    /// The curves (first seed, with `series`).
    #[serde(skip)]
    pub series: Option<LawSeries>,
}

/// One law over every seed.
#[derive(Debug, Clone, Serialize)]
pub struct LawRow {
    /// The row's name: the law's, or the label of a user's controller.
    pub name: String,
    /// The law, whether it is model-based, and its parameters (for a
    /// user's controller: the scenario's law, whose gains it was given).
    pub law: LawInfo,
    /// A user's controller: its command and what it declared.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub external: Option<ExternalRow>,
    /// Each seed's run.
    pub runs: Vec<LawRun>,
    /// Per metric, the median over seeds.
    pub median: Stats,
    /// Per metric, the first quartile over seeds (linear interpolation).
    pub q1: Stats,
    /// Per metric, the third quartile.
    pub q3: Stats,
    /// Per metric, the low end of the 95 % interval of the median
    /// ([`analysis::stats::median_interval`]: order statistics).
    pub ci95_low: Stats,
    /// Per metric, its high end.
    pub ci95_high: Stats,
    /// The interval's ranks and coverage (the same for every metric).
    pub ci95: Option<IntervalRanks>,
    /// Per metric, the worst seed's value.
    pub worst: Stats,
    /// Seeds whose run kept |e| < k_c for every t ≥ T_c ([`Envelope`]).
    pub kept_envelope: u64,
    /// Seeds whose run left it after T_c.
    pub left_envelope: u64,
    /// Seeds whose run ended before T_c.
    pub not_judged: u64,
    /// Seeds whose run failed ([`failed_because`]).
    pub failed: u64,
}

/// The whole comparison.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// Scenario name.
    pub scenario: String,
    /// Where it came from.
    pub scenario_source: String,
    /// The robot.
    pub robot: String,
    /// Sim time per run, s.
    pub duration_s: f64,
    /// Seeds per law.
    pub seeds: u64,
    /// Worker threads used.
    pub threads: usize,
    /// Wall time of all runs, s.
    pub wall_time_s: f64,
    /// One row per law.
    pub laws: Vec<LawRow>,
    /// The baseline (nac, else the first law) against each other law on the same seeds (with two
    /// seeds or more).
    pub paired: Vec<Paired>,
    /// What this says about the paper's claims ([`crate::compare_findings`]).
    pub findings: Vec<crate::compare_findings::Finding>,
    /// What limits what the seeds say: identical seeds (nothing random),
    /// or one draw of random effects.
    pub warnings: Vec<String>,
    /// The scenario's random effects (empty: a deterministic scenario).
    pub random_effects: Vec<String>,
}

/// A paired test of the baseline (nac, else the first law) against another on one metric.
#[derive(Debug, Clone, Serialize)]
pub struct Paired {
    /// The baseline: `nac` when it runs, else the first row, whatever the
    /// rows' order.
    pub law: String,
    /// The row it is tested against.
    pub versus: String,
    /// The metric.
    pub metric: &'static str,
    /// Wilcoxon signed-rank of law − versus, seed by seed: `a_smaller` is
    /// the seeds where `law` did better.
    pub test: SignedRank,
    /// The test's p-value Holm-corrected over every paired test of the
    /// comparison (what the findings use).
    pub p_holm: f64,
}

/// Which order statistics bound the 95 % interval of the median, and its
/// coverage ([`analysis::stats::median_interval`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IntervalRanks {
    /// The low end is the k-th smallest value (1-based).
    pub k: usize,
    /// The high end is the (n + 1 − k)-th.
    pub high_rank: usize,
    /// P(low ≤ median ≤ high) for a continuous distribution.
    pub coverage: f64,
}

impl From<(MedianInterval, usize)> for IntervalRanks {
    fn from((m, n): (MedianInterval, usize)) -> Self {
        Self {
            k: m.k,
            high_rank: n + 1 - m.k,
            coverage: m.coverage,
        }
    }
}

/// The plan of `testbed sim --law <law>` with seed `plan.seed + s`: the
/// scenario before its draws, for `law`, with that seed's `[randomise]`
/// draws (the same for every law).
pub fn plan_for(
    plan: &Plan,
    law: LawName,
    s: u64,
    tuning: Option<Tuning>,
) -> Result<Plan, CompareError> {
    let mut scenario = plan.undrawn.clone();
    scenario.controller = scenario.controller.for_law(law);
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

/// Runs every law on every seed and scores them.
pub fn compare(plan: &Plan, opts: &CompareOptions) -> Result<Comparison, CompareError> {
    if (opts.laws.is_empty() && opts.external.is_empty()) || opts.seeds == 0 {
        return Err(CompareError::Empty(
            "compare needs at least one law and one seed",
        ));
    }
    let mut jobs = Vec::new();
    for &law in &opts.laws {
        for s in 0..opts.seeds {
            jobs.push((law, s, plan_for(plan, law, s, opts.tuning)?));
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
    let bar = crate::sweep::progress_bar(opts.progress, total);
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
    let identical = opts.seeds > 1 && crate::compare_scores::identical_seeds(&laws);
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
    };
    c.findings = crate::compare_findings::findings(&c);
    Ok(c)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_law_is_an_error() {
        let plan = scenario::load(None, &scenario::Overrides::default()).unwrap();
        let opts = CompareOptions {
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
