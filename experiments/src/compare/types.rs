//! The data of a comparison: what it is asked (`CompareOptions`), what
//! each run and law gives, and what it finds. Every other file of `compare`
//! builds on these; this file imports none of them.

use analysis::law_info::LawInfo;
use analysis::stats::{MedianInterval, SignedRank};
use analysis::summary::Summary;
use analysis::timing::Percentiles;
use controller::{LawName, Tuning};
use serde::Serialize;

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
    /// A law listed twice: two rows of one name.
    #[error("{0} is listed twice: each law is one row of the table")]
    DuplicateLaw(LawName),
    /// A `--law-set` that the law's parameters cannot take.
    #[error("--law-set {law}:controller.{key}: {}", cause.message())]
    LawSet {
        /// The law.
        law: LawName,
        /// The key.
        key: String,
        /// Why the parameters do not read with it.
        cause: toml::de::Error,
    },
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
    /// One law's own keys (`--law-set mpc:controller.mpc_step=0.02`), set
    /// on that law's parameters only, after the scenario's.
    pub law_sets: Vec<LawSet>,
}

/// A controller key set for one law of a comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct LawSet {
    /// The law whose runs get it.
    pub law: LawName,
    /// The key under `[controller]` (without the `controller.` prefix).
    pub key: String,
    /// Its value, checked like the scenario file.
    pub value: toml::Value,
}

impl std::str::FromStr for LawSet {
    type Err = String;

    /// `LAW:controller.KEY=VALUE`: the law by name, a key it takes, a TOML
    /// value (as `--set` reads it).
    fn from_str(arg: &str) -> Result<Self, String> {
        let Some((law, set)) = arg.split_once(':') else {
            return Err(format!("{arg:?} is not LAW:controller.KEY=VALUE"));
        };
        let law: LawName = law.trim().parse()?;
        let (key, value) = scenario::parse_set(set).map_err(|e| e.to_string())?;
        let Some(key) = key.strip_prefix("controller.") else {
            return Err(format!("{key}: only controller keys are set per law"));
        };
        if !law.takes(key) {
            return Err(format!(
                "{law} does not take controller.{key} (it takes {})",
                law.keys().join(", ")
            ));
        }
        Ok(Self {
            law,
            key: key.to_string(),
            value,
        })
    }
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
    /// Why the run failed, if it did ([`failed_because`](crate::compare::scores::failed_because): it could not be
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
    /// Per metric, the interquartile mean over seeds
    /// ([`analysis::stats::iqm`]).
    pub iqm: Stats,
    /// Per metric, the low end of the IQM's bootstrap 95 % interval
    /// ([`analysis::stats::iqm_interval`], seeded).
    pub iqm_ci95_low: Stats,
    /// Per metric, its high end.
    pub iqm_ci95_high: Stats,
    /// Seeds whose run kept |e| < k_c for every t ≥ T_c ([`Envelope`]).
    pub kept_envelope: u64,
    /// Seeds whose run left it after T_c.
    pub left_envelope: u64,
    /// Seeds whose run ended before T_c.
    pub not_judged: u64,
    /// Seeds whose run failed ([`failed_because`](crate::compare::scores::failed_because)).
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
    /// What this says about the paper's claims ([`crate::compare::findings`]).
    pub findings: Vec<Finding>,
    /// What limits what the seeds say: identical seeds (nothing random),
    /// or one draw of random effects.
    pub warnings: Vec<String>,
    /// The scenario's random effects (empty: a deterministic scenario).
    pub random_effects: Vec<String>,
    /// How the laws that take a tuning rule turned K1, K2 into their gains.
    pub tuning: Tuning,
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
    /// The median over seeds of (law − versus) / |versus|
    /// ([`analysis::stats::median_relative_difference`]; JSON null where
    /// infinite: a failed run on one side).
    pub median_relative_difference: f64,
    /// "law is lower than versus" by the findings' rule
    /// ([`Verdict::of_paired`]) at this p_holm; `not-tested` where the two
    /// gave the same value bit for bit on every seed.
    pub verdict: Verdict,
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

/// One value per metric of [`METRICS`](crate::compare::scores::METRICS), in order (JSON: an object; an
/// infinite value, i.e. a missing one counted as the worst, is null).
#[derive(Debug, Clone, PartialEq)]
pub struct Stats(pub Vec<(&'static str, f64)>);

impl Stats {
    /// The value of metric `name`.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.0.iter().find(|(k, _)| *k == name).map(|(_, v)| *v)
    }
}

impl Serialize for Stats {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            map.serialize_entry(k, &v.is_finite().then_some(*v))?;
        }
        map.end()
    }
}

/// Whether a run kept |e_i| < k_c,i for every joint and every t ≥ T_c.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Envelope {
    /// Inside at every step from T_c on.
    Kept,
    /// At or outside it at some step from T_c on (a non-finite error counts
    /// as outside).
    Left,
    /// The run ended before T_c: nothing to judge.
    NotJudged,
}

impl Envelope {
    /// The run's envelope fact, from its summary.
    pub fn of(s: &Summary) -> Self {
        let judged = s.joints.iter().any(|j| j.min_margin_after_tc.is_some());
        match (judged, s.constraint_satisfied_after_tc) {
            (false, _) => Self::NotJudged,
            (true, true) => Self::Kept,
            (true, false) => Self::Left,
        }
    }

    /// As the table and the CSV write it.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Kept => "kept",
            Self::Left => "left",
            Self::NotJudged => "not-judged",
        }
    }
}

/// A paired median relative difference smaller than this is "no
/// difference".
pub const MATTERS: f64 = 0.01;
/// The family-wise level of the findings' tests (on Holm-corrected p).
pub const ALPHA: f64 = 0.05;

/// A claim's verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// The rule of the claim is met (for a comparison: its paired test
    /// is significant after the Holm correction, and the effect counts).
    Holds,
    /// It is not: for a comparison, the paired test is significant the
    /// other way.
    DoesNotHold,
    /// The paired test is not significant (or the effect is under the
    /// size that counts): the data do not show it either way.
    NotShown,
    /// The comparison lacks a law or a situation the claim needs.
    NotTested,
    /// Every run ended before T_c: the constraint was never in force.
    NotJudged,
}

impl Verdict {
    /// The findings' rule for "a is lower than b", one definition for the
    /// claims and for every paired test of a comparison: significant after
    /// Holm and ahead by at least [`MATTERS`] holds; significant and behind
    /// by as much does not hold; anything else is not shown.
    pub fn of_paired(significant: bool, ahead_by_enough: bool, behind_by_enough: bool) -> Self {
        match (significant, ahead_by_enough, behind_by_enough) {
            (true, true, _) => Verdict::Holds,
            (true, _, true) => Verdict::DoesNotHold,
            _ => Verdict::NotShown,
        }
    }
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Holds => "holds",
            Self::DoesNotHold => "does not hold",
            Self::NotShown => "not shown",
            Self::NotTested => "not tested",
            Self::NotJudged => "not judged",
        })
    }
}

/// One claim on one scenario.
#[derive(Debug, Clone, Serialize)]
pub struct Finding {
    /// The claim, briefly.
    pub claim: String,
    /// The verdict by the module's rules.
    pub verdict: Verdict,
    /// The numbers it rests on.
    pub evidence: String,
}

/// A user's controller in the table: its row's label and its command.
#[derive(Debug, Clone, PartialEq)]
pub struct ExternalSpec {
    /// The row's name.
    pub label: String,
    /// The program and its arguments.
    pub command: Vec<String>,
}

/// What a row of a user's controller says about it.
#[derive(Debug, Clone, Serialize)]
pub struct ExternalRow {
    /// The command.
    pub command: String,
    /// The law it declared (`CMD --describe`) with its parameters, if it
    /// declared one.
    pub declared: Option<analysis::report::ExternalLaw>,
}
