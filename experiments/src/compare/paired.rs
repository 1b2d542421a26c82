//! How one law's runs compare with another's on the same seeds, as the
//! findings print it ([`crate::compare::findings`]): a metric's values
//! per seed, the paired relative effect (the median of per-seed relative
//! differences, never a ratio of medians), blow-ups, failures and torque
//! saturation named, and the numbers' printed form.

use crate::compare::scores::stats_of;
use crate::compare::types::{LawRow, LawRun};

/// One law's value this many times the other's on a seed is a blow-up.
pub const BLOW_UP: f64 = 100.0;

/// The first `runs` values of `metric` of a row (a missing one is the
/// worst, +∞ or −∞, as in the table).
pub(crate) fn values(r: &LawRow, metric: &str, runs: usize) -> Vec<f64> {
    r.runs.iter().take(runs).map(|x| value(x, metric)).collect()
}

fn value(run: &LawRun, metric: &str) -> f64 {
    stats_of(run).get(metric).unwrap_or(f64::NAN)
}

/// Blow-ups and torque saturation of either law, named.
pub(crate) fn extremes(nac: &LawRow, o: &LawRow, a: &[f64], b: &[f64]) -> String {
    let mut out = String::new();
    for (name, mine, theirs) in [(&nac.name, a, b), (&o.name, b, a)] {
        let failed = mine.iter().filter(|x| !x.is_finite()).count();
        let blown: Vec<f64> = mine
            .iter()
            .zip(theirs)
            .filter(|(x, y)| x.is_finite() && y.is_finite() && **x > BLOW_UP * y.abs().max(1e-300))
            .map(|(x, y)| x / y.abs().max(1e-300))
            .collect();
        if failed > 0 {
            out.push_str(&format!(
                "; {name} failed on {failed} seeds (scored as the worst)"
            ));
        }
        if let Some(worst) = blown.iter().copied().reduce(f64::max) {
            out.push_str(&format!(
                "; {name} blew up on {} seeds (up to {worst:.2e} times the other's value)",
                blown.len()
            ));
        }
    }
    for r in [nac, o] {
        let saturated = r
            .runs
            .iter()
            .filter(|x| x.summary.metrics.saturated_s > 0.0)
            .count();
        if saturated > 0 {
            out.push_str(&format!(
                "; {} saturated its torque on {saturated} of {} seeds (median {} s)",
                r.name,
                r.runs.len(),
                num(r.median.get("saturated_s"))
            ));
        }
    }
    out
}

pub(crate) fn percent(rel: f64) -> String {
    if rel.is_finite() {
        format!("{:+.2} %", 100.0 * rel)
    } else if rel < 0.0 {
        "the other failed".into()
    } else {
        "nac failed".into()
    }
}

pub(crate) fn num(x: Option<f64>) -> String {
    match x {
        Some(v) if v.is_finite() => format!("{v:.4}"),
        Some(_) => "failed".into(),
        None => "n/a".into(),
    }
}
