//! How `testbed compare` scores a law: the metrics of BASELINES.md and
//! which way each is worse; three facts about each run, by one rule for
//! every law: whether it failed (could not be scored: it stopped early,
//! went non-finite or faulted; a failed run scores as the worst, never the
//! best), whether it kept |e| < k_c after T_c (kept, left, or not judged
//! when it ended before T_c), and how often the law's guard acted
//! (breaches, a metric); a law's row over its seeds (median, IQR, 95 %
//! interval, worst); and the paired tests of a baseline (nac when it runs,
//! else the first law) against each other law, Holm-corrected.

use analysis::law_info::LawInfo;
use analysis::stats::{
    iqm, iqm_interval, median_interval, median_relative_difference, quantile, signed_rank,
};
use analysis::summary::Summary;

use crate::compare::types::{
    ALPHA, Envelope, IntervalRanks, LawRow, LawRun, MATTERS, Paired, Stats, Verdict,
};

/// The metrics of the paired tests: error, peak error, effort beyond the
/// gravity hold, energy.
pub const PAIRED_METRICS: [&str; 4] = [
    "iae",
    "max_abs_error",
    "effort_beyond_gravity",
    "energy_after_tc",
];

/// A metric of the table: its name, unit and which way is worse.
pub struct Metric {
    /// Name (JSON key and column).
    pub name: &'static str,
    /// Unit, for headings.
    pub unit: &'static str,
    /// Larger is worse (false: smaller is worse, as for the margin).
    pub larger_is_worse: bool,
    get: fn(&LawRun) -> Option<f64>,
}

/// BASELINES.md's metrics, in table order. A missing value (the run ended
/// before T_c, or never entered the envelope for good) counts as the worst.
pub const METRICS: &[Metric] = &[
    m("iae", "rad s", true, |r| r.summary.metrics.iae_after_tc),
    m("ise", "rad² s", true, |r| r.summary.metrics.ise_after_tc),
    m("itae", "rad s²", true, |r| r.summary.metrics.itae_after_tc),
    m("max_abs_error", "rad", true, |r| {
        r.summary.metrics.max_abs_error_after_tc
    }),
    m("min_margin", "rad", false, |r| {
        r.summary.metrics.min_margin_after_tc
    }),
    m("entered_s", "s", true, |r| {
        r.summary.metrics.entered_envelope_s
    }),
    m("violation_s", "s", true, |r| {
        Some(r.summary.metrics.violation_s)
    }),
    m("violation_after_tc_s", "s", true, |r| {
        Some(r.summary.metrics.violation_after_tc_s)
    }),
    m("effort_after_tc", "N² m² s", true, |r| {
        Some(r.summary.metrics.effort_after_tc)
    }),
    m("effort_beyond_gravity", "N² m² s", true, |r| {
        r.summary.metrics.effort_beyond_gravity_after_tc
    }),
    m("energy_after_tc", "J", true, |r| {
        Some(r.summary.metrics.energy_after_tc)
    }),
    m("torque_rate", "N² m²/s", true, |r| {
        Some(r.summary.metrics.torque_rate)
    }),
    m("torque_smoothness", "N m", true, |r| {
        r.summary.metrics.torque_smoothness
    }),
    m("peak_torque", "N m", true, |r| {
        Some(r.summary.metrics.peak_abs_torque)
    }),
    m("saturated_s", "s", true, |r| {
        Some(r.summary.metrics.saturated_s)
    }),
    m("breaches", "steps", true, |r| {
        Some(r.summary.metrics.breaches as f64)
    }),
    m("peak_actor_torque", "N m", true, |r| {
        Some(r.summary.metrics.peak_actor_torque)
    }),
    m("compute_p50_us", "µs", true, |r| Some(r.compute_us.p50)),
    m("compute_p99_us", "µs", true, |r| Some(r.compute_us.p99)),
];

const fn m(
    name: &'static str,
    unit: &'static str,
    larger_is_worse: bool,
    get: fn(&LawRun) -> Option<f64>,
) -> Metric {
    Metric {
        name,
        unit,
        larger_is_worse,
        get,
    }
}

/// Every metric of one run (missing values as the worst, ±∞).
pub fn stats_of(run: &LawRun) -> Stats {
    Stats(METRICS.iter().map(|m| (m.name, value(m, run))).collect())
}

fn value(metric: &Metric, run: &LawRun) -> f64 {
    let bad = if metric.larger_is_worse {
        f64::INFINITY
    } else {
        f64::NEG_INFINITY
    };
    if run.failed.is_some() {
        // A faulted run's "effort 0" is not the best effort (#26).
        return bad;
    }
    (metric.get)(run).filter(|x| !x.is_nan()).unwrap_or(bad)
}

/// Why a run failed, if it did: it could not be scored, because it
/// stopped early, or went non-finite, or the law faulted (published zero
/// torque). The same rule for every law: guard breaches and leaving the
/// envelope are facts of their own ([`Envelope`], the `breaches` metric),
/// never a failure.
pub fn failed_because(failure: Option<&str>, s: &Summary) -> Option<String> {
    let mut why = Vec::new();
    if let Some(f) = failure {
        why.push(format!("stopped: {f}"));
    }
    if !s.finite {
        why.push(format!(
            "non-finite signals or faults ({} fault steps)",
            s.fault_steps
        ));
    }
    (!why.is_empty()).then(|| why.join("; "))
}

/// A run scored: its failure (if any) and its envelope fact, from its
/// summary.
pub fn scored(
    seed: u64,
    failure: Option<String>,
    summary: Summary,
    compute_us: analysis::timing::Percentiles,
    series: Option<crate::compare::types::LawSeries>,
) -> LawRun {
    LawRun {
        seed,
        failed: failed_because(failure.as_deref(), &summary),
        envelope: Envelope::of(&summary),
        failure,
        summary,
        compute_us,
        series,
    }
}

/// The bootstrap's seed for every row's IQM interval.
const IQM_BOOTSTRAP_SEED: u64 = 0;

pub(crate) fn row(law: LawInfo, runs: Vec<LawRun>) -> LawRow {
    let mut rows: [Vec<(&'static str, f64)>; 9] = Default::default();
    let mut ci95 = None;
    for metric in METRICS {
        let mut v: Vec<f64> = runs.iter().map(|r| value(metric, r)).collect();
        v.sort_by(f64::total_cmp);
        let w = if metric.larger_is_worse {
            v[v.len() - 1]
        } else {
            v[0]
        };
        let interval = median_interval(&v);
        ci95 = interval.map(|i| IntervalRanks::from((i, v.len())));
        let (lo, hi) = interval.map_or((f64::NAN, f64::NAN), |c| (c.low, c.high));
        // One bootstrap seed for every row: the intervals of two laws on
        // the same seeds resample alike.
        let (iqm_lo, iqm_hi) =
            iqm_interval(&[&v], IQM_BOOTSTRAP_SEED).unwrap_or((f64::NAN, f64::NAN));
        let values = [
            median_of(&v),
            quantile(&v, 0.25),
            quantile(&v, 0.75),
            lo,
            hi,
            w,
            iqm(&v),
            iqm_lo,
            iqm_hi,
        ];
        for (r, x) in rows.iter_mut().zip(values) {
            r.push((metric.name, x));
        }
    }
    let count = |e: Envelope| runs.iter().filter(|r| r.envelope == e).count() as u64;
    let (kept, left, not_judged) = (
        count(Envelope::Kept),
        count(Envelope::Left),
        count(Envelope::NotJudged),
    );
    let failed = runs.iter().filter(|r| r.failed.is_some()).count() as u64;
    let [
        median,
        q1,
        q3,
        ci95_low,
        ci95_high,
        worst,
        iqm,
        iqm_ci95_low,
        iqm_ci95_high,
    ] = rows.map(Stats);
    LawRow {
        name: law.law.to_string(),
        law,
        external: None,
        runs,
        median,
        q1,
        q3,
        ci95_low,
        ci95_high,
        ci95,
        worst,
        iqm,
        iqm_ci95_low,
        iqm_ci95_high,
        kept_envelope: kept,
        left_envelope: left,
        not_judged,
        failed,
    }
}

/// The row the paired tests compare every other law with: `nac` (the
/// testbed's own) when it runs, else the first row.
pub(crate) fn baseline(laws: &[LawRow]) -> Option<usize> {
    laws.iter()
        .position(|r| r.law.law == controller::LawName::Nac && r.external.is_none())
        .or((!laws.is_empty()).then_some(0))
}

/// The baseline against every other law, per [`PAIRED_METRICS`], seed by
/// seed (seeds are the same runs' draws for every law), with the p-values
/// Holm-corrected over all of them.
pub(crate) fn paired(laws: &[LawRow]) -> Vec<Paired> {
    let Some(b) = baseline(laws) else {
        return Vec::new();
    };
    let first = &laws[b];
    if first.runs.len() < 2 {
        return Vec::new();
    }
    let values = |row: &LawRow, name: &str| -> Vec<f64> {
        let metric = METRICS.iter().find(|m| m.name == name);
        row.runs
            .iter()
            .map(|r| metric.map_or(f64::NAN, |m| value(m, r)))
            .collect()
    };
    let mut tests: Vec<Paired> = laws
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != b)
        .flat_map(|(_, other)| {
            PAIRED_METRICS.iter().map(move |&metric| {
                let (a, b) = (values(first, metric), values(other, metric));
                let test = signed_rank(&a, &b);
                let identical = a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits());
                Paired {
                    law: first.name.clone(),
                    versus: other.name.clone(),
                    metric,
                    p_holm: test.p_value,
                    median_relative_difference: median_relative_difference(&a, &b),
                    // Set once Holm has corrected every p below.
                    verdict: if identical {
                        Verdict::NotTested
                    } else {
                        Verdict::NotShown
                    },
                    test,
                }
            })
        })
        .collect();
    let adjusted = holm(&tests.iter().map(|t| t.test.p_value).collect::<Vec<_>>());
    for (t, p) in tests.iter_mut().zip(adjusted) {
        t.p_holm = p;
        if t.verdict != Verdict::NotTested {
            let rel = t.median_relative_difference;
            t.verdict = Verdict::of_paired(
                p < ALPHA,
                t.test.a_smaller > t.test.b_smaller && rel <= -MATTERS,
                t.test.b_smaller > t.test.a_smaller && rel >= MATTERS,
            );
        }
    }
    tests
}

/// Holm's step-down correction of `p` (family-wise error over all of
/// them): the k-th smallest becomes max over j ≤ k of min(1, (m − j + 1) p_(j)).
pub fn holm(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let mut out = vec![f64::NAN; m];
    let mut running = 0.0_f64;
    for (j, &i) in order.iter().enumerate() {
        running = running.max(((m - j) as f64 * p[i]).min(1.0));
        out[i] = running;
    }
    out
}

/// Whether every seed gave the same run for every law (a scenario with
/// nothing random): then N seeds are one run, and no test is made. Compute
/// times, which are this machine's, are left out.
pub(crate) fn identical_seeds(laws: &[LawRow]) -> bool {
    let same = |a: &LawRun, b: &LawRun| {
        let (a, b) = (stats_of(a), stats_of(b));
        a.0.iter()
            .zip(&b.0)
            .filter(|((k, _), _)| !k.starts_with("compute_"))
            .all(|((_, x), (_, y))| x.to_bits() == y.to_bits())
    };
    laws.iter().all(|row| match row.runs.split_first() {
        Some((first, rest)) => !rest.is_empty() && rest.iter().all(|r| same(first, r)),
        None => false,
    })
}

/// The median of sorted values (mean of the middle two for an even count).
fn median_of(v: &[f64]) -> f64 {
    let k = v.len() / 2;
    if v.len() % 2 == 1 {
        v[k]
    } else {
        let (a, b) = (v[k - 1], v[k]);
        // ∞ in the middle stays ∞ (not NaN from ∞ − ∞).
        if a == b { a } else { 0.5 * (a + b) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holm_scales_by_rank_and_stays_monotone() {
        let p = holm(&[0.01, 0.04, 0.03, 0.005]);
        // Sorted 0.005, 0.01, 0.03, 0.04 times 4, 3, 2, 1: 0.02, 0.03, 0.06, 0.06.
        let want = [0.03, 0.06, 0.06, 0.02];
        for (a, b) in p.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{p:?}");
        }
        assert_eq!(holm(&[0.9, 0.8]), vec![1.0, 1.0]);
        assert!(holm(&[]).is_empty());
    }

    #[test]
    fn median_and_worst_treat_missing_values_as_worst() {
        assert_eq!(median_of(&[1.0, 2.0, 3.0]), 2.0);
        assert_eq!(median_of(&[1.0, 2.0, 3.0, 10.0]), 2.5);
        assert_eq!(
            median_of(&[1.0, f64::INFINITY, f64::INFINITY]),
            f64::INFINITY
        );
        assert_eq!(median_of(&[f64::INFINITY, f64::INFINITY]), f64::INFINITY);
    }
}
