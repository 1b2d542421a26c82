//! How `testbed compare` scores a law: the metrics of BASELINES.md and
//! which way each is worse, why a run failed (a failed run scores as the
//! worst, never the best), a law's row over its seeds (median, IQR, 95 %
//! interval, worst) and the paired test of the first law against each other.

use analysis::law_info::LawInfo;
use analysis::stats::{median_interval, quantile, signed_rank};
use analysis::summary::Summary;
use serde::Serialize;

use crate::compare::{IntervalRanks, LawRow, LawRun, Paired};

/// The metrics of the paired tests: error, peak error, effort, energy.
pub const PAIRED_METRICS: [&str; 4] =
    ["iae", "max_abs_error", "effort_after_tc", "energy_after_tc"];

/// One value per metric of [`METRICS`], in order (JSON: an object; an
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
    m("energy_after_tc", "J", true, |r| {
        Some(r.summary.metrics.energy_after_tc)
    }),
    m("torque_rate", "N² m²/s", true, |r| {
        Some(r.summary.metrics.torque_rate)
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

/// Barrier breaches a run may have and still count: a few steps of the
/// guard acting are the law at work; more is a law fighting its barrier.
pub const BREACHES_ALLOWED: u64 = 100;

/// Why a run failed, if it did: it stopped early, went non-finite or
/// faulted, breached its barrier more than [`BREACHES_ALLOWED`] steps, or
/// left the envelope after T_c. (A run that ends before T_c is not judged
/// on the constraint.)
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
    if s.barrier_breached_steps > BREACHES_ALLOWED {
        why.push(format!("{} barrier breaches", s.barrier_breached_steps));
    }
    let judged = s.joints.iter().any(|j| j.min_margin_after_tc.is_some());
    if judged && !s.constraint_satisfied_after_tc {
        why.push("left the envelope after T_c".into());
    }
    (!why.is_empty()).then(|| why.join("; "))
}

pub(crate) fn row(law: LawInfo, runs: Vec<LawRun>) -> LawRow {
    let mut rows: [Vec<(&'static str, f64)>; 6] = Default::default();
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
        let values = [
            median_of(&v),
            quantile(&v, 0.25),
            quantile(&v, 0.75),
            lo,
            hi,
            w,
        ];
        for (r, x) in rows.iter_mut().zip(values) {
            r.push((metric.name, x));
        }
    }
    let kept = runs
        .iter()
        .filter(|r| r.failed.is_none())
        .filter(|r| r.summary.constraint_satisfied_after_tc)
        .count() as u64;
    let [median, q1, q3, ci95_low, ci95_high, worst] = rows.map(Stats);
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
        kept_envelope: kept,
    }
}

/// The first law against every other, per [`PAIRED_METRICS`], seed by
/// seed (seeds are the same runs' draws for every law).
pub(crate) fn paired(laws: &[LawRow]) -> Vec<Paired> {
    let Some((first, others)) = laws.split_first() else {
        return Vec::new();
    };
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
    others
        .iter()
        .flat_map(|other| {
            PAIRED_METRICS.iter().map(move |&metric| Paired {
                law: first.name.clone(),
                versus: other.name.clone(),
                metric,
                test: signed_rank(&values(first, metric), &values(other, metric)),
            })
        })
        .collect()
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
