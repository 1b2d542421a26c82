//! What a comparison says about the paper's claims, with the numbers, by
//! stated rules (so that a reader can check each verdict):
//!
//! 1. *Inside the envelope after T_c*: holds when every `nac` run kept
//!    |e| < k_c for every t ≥ T_c and none failed.
//! 2. *Starting outside*: tested when some `nac` run was outside the
//!    envelope before T_c (violation before T_c > 0); holds when every
//!    such run was inside for good by T_c and did not fail.
//! 3. *Energy after T_c*: `nac`'s median effort ∫τ² after T_c against
//!    `pd`'s and `blf`'s, and its mechanical energy ∫|τ q̇| against `pd`'s: holds against a law when it is lower by at least
//!    [`MATTERS`] (or the other's median failed and `nac`'s did not) and,
//!    with two seeds or more, the paired test agrees (p < [`ALPHA`], `nac`
//!    better on more seeds).
//! 4. *What the actor–critic adds*: `nac` against `nac-no-networks` on
//!    IAE after T_c, by the same rule.
//!
//! A claim whose law is not in the comparison is "not tested".

use controller::LawName;
use serde::Serialize;

use crate::compare::{Comparison, LawRow, Paired};

/// A relative difference smaller than this is "no difference".
pub const MATTERS: f64 = 0.01;
/// The paired test's level.
pub const ALPHA: f64 = 0.05;

/// A claim's verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// The rule of the claim is met.
    Holds,
    /// It is not.
    DoesNotHold,
    /// The comparison lacks a law or a situation the claim needs.
    NotTested,
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Holds => "holds",
            Self::DoesNotHold => "does not hold",
            Self::NotTested => "not tested",
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

/// Every claim's finding on `c`.
pub fn findings(c: &Comparison) -> Vec<Finding> {
    let Some(nac) = row(c, LawName::Nac) else {
        let none = |claim: &str| Finding {
            claim: claim.into(),
            verdict: Verdict::NotTested,
            evidence: "nac is not in the comparison".into(),
        };
        return CLAIMS.iter().map(|c| none(c)).collect();
    };
    let mut out = vec![inside(nac), outside(c, nac)];
    for other in [LawName::Pd, LawName::Blf] {
        out.push(better(c, nac, other, "effort_after_tc", CLAIMS[2]));
    }
    out.push(better(c, nac, LawName::NacNoNetworks, "iae", CLAIMS[3]));
    out.push(better(c, nac, LawName::Pd, "energy_after_tc", CLAIMS[2]));
    out
}

const CLAIMS: [&str; 4] = [
    "nac keeps |e| < k_c after T_c",
    "nac may start outside the envelope and is inside by T_c",
    "nac uses less energy after T_c",
    "the actor-critic lowers the error after T_c",
];

fn row(c: &Comparison, law: LawName) -> Option<&LawRow> {
    c.laws
        .iter()
        .find(|r| r.law.law == law && r.external.is_none())
}

fn inside(nac: &LawRow) -> Finding {
    let n = nac.runs.len();
    let failed = nac.runs.iter().filter(|r| r.failed.is_some()).count();
    let ok = nac.kept_envelope as usize == n && failed == 0;
    Finding {
        claim: CLAIMS[0].into(),
        verdict: if ok {
            Verdict::Holds
        } else {
            Verdict::DoesNotHold
        },
        evidence: format!(
            "kept on {} of {n} seeds ({failed} failed); median min margin k_c - |e| after T_c {}, median max |e| {}",
            nac.kept_envelope,
            num(nac.median.get("min_margin")),
            num(nac.median.get("max_abs_error")),
        ),
    }
}

fn outside(c: &Comparison, nac: &LawRow) -> Finding {
    let early: Vec<_> = nac
        .runs
        .iter()
        .filter(|r| {
            let m = &r.summary.metrics;
            m.violation_s - m.violation_after_tc_s > 0.0
        })
        .collect();
    let tc = nac.runs.first().map_or(f64::NAN, |r| r.summary.tc_s);
    let entered = early
        .iter()
        .filter(|r| r.failed.is_none())
        .filter(|r| {
            r.summary
                .metrics
                .entered_envelope_s
                .is_some_and(|t| t <= tc)
        })
        .count();
    let shift = row(c, LawName::NacNoShift).map_or(String::new(), |r| {
        let failed = r.runs.iter().filter(|x| x.failed.is_some()).count();
        let mut breaches: Vec<u64> = r.runs.iter().map(|x| x.summary.barrier_breached_steps).collect();
        breaches.sort_unstable();
        format!(
            "; with the constraint on from t = 0 (nac-no-shift): median {} barrier breaches, {failed} of {} seeds failed",
            breaches.get(breaches.len() / 2).copied().unwrap_or(0),
            r.runs.len()
        )
    });
    let verdict = match (early.len(), entered == early.len()) {
        (0, _) => Verdict::NotTested,
        (_, true) => Verdict::Holds,
        (_, false) => Verdict::DoesNotHold,
    };
    Finding {
        claim: CLAIMS[1].into(),
        verdict,
        evidence: format!(
            "outside before T_c = {tc} s on {} of {} seeds, inside for good by T_c on {entered} of them (median entry {} s){shift}",
            early.len(),
            nac.runs.len(),
            num(nac.median.get("entered_s")),
        ),
    }
}

/// `nac` against `other` on `metric` (smaller is better), by the rule of
/// the module's claims 3 and 4.
fn better(c: &Comparison, nac: &LawRow, other: LawName, metric: &str, claim: &str) -> Finding {
    let claim = format!("{claim} (vs {other}, {metric})");
    let Some(o) = row(c, other) else {
        return Finding {
            claim,
            verdict: Verdict::NotTested,
            evidence: format!("{other} is not in the comparison"),
        };
    };
    let (a, b) = (
        nac.median.get(metric).unwrap_or(f64::NAN),
        o.median.get(metric).unwrap_or(f64::NAN),
    );
    let rel = (a - b) / b.abs();
    let test = paired(c, other, metric);
    let agrees = test.is_none_or(|p| p.test.p_value < ALPHA && p.test.a_smaller > p.test.b_smaller);
    // A failed median is the worst value: below it is lower.
    let lower = a.is_finite() && (!b.is_finite() || rel <= -MATTERS);
    let verdict = match (lower && agrees, a.is_finite() || b.is_finite()) {
        (true, _) => Verdict::Holds,
        (false, true) => Verdict::DoesNotHold,
        (false, false) => Verdict::NotTested,
    };
    let p = test.map_or(String::from("one seed, no paired test"), |p| {
        format!(
            "nac better on {} of {} seeds, worse on {}, Wilcoxon p = {:.2e}",
            p.test.a_smaller, p.test.pairs, p.test.b_smaller, p.test.p_value
        )
    });
    Finding {
        claim,
        verdict,
        evidence: format!(
            "median nac {} vs {other} {} ({}); {p}",
            num(Some(a)),
            num(Some(b)),
            if rel.is_finite() {
                format!("{:+.2} %", 100.0 * rel)
            } else {
                "a failed median".into()
            }
        ),
    }
}

fn paired<'a>(c: &'a Comparison, other: LawName, metric: &str) -> Option<&'a Paired> {
    c.paired.iter().find(|p| {
        p.law == LawName::Nac.to_string() && p.versus == other.to_string() && p.metric == metric
    })
}

fn num(x: Option<f64>) -> String {
    match x {
        Some(v) if v.is_finite() => format!("{v:.4}"),
        Some(_) => "failed".into(),
        None => "n/a".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::{CompareOptions, compare};

    fn run(laws: Vec<LawName>) -> Comparison {
        let plan = scenario::load(
            None,
            &scenario::Overrides {
                duration_s: Some(4.0),
                ..Default::default()
            },
        )
        .unwrap();
        let opts = CompareOptions {
            external: Vec::new(),
            runs_dir: std::path::PathBuf::from("runs"),
            progress: false,
            laws,
            seeds: 1,
            threads: Some(1),
            series: false,
            tuning: None,
        };
        compare(&plan, &opts).unwrap()
    }

    #[test]
    fn the_paper_scenario_starts_outside_and_keeps_the_envelope() {
        let c = run(vec![LawName::Nac, LawName::Pd]);
        let f = findings(&c);
        assert_eq!(f.len(), 6);
        assert!(f[5].claim.contains("energy_after_tc"), "{:?}", f[5]);
        assert_eq!(f[0].verdict, Verdict::Holds, "{:?}", f[0]);
        assert_eq!(f[1].verdict, Verdict::Holds, "{:?}", f[1]);
        assert!(f[1].evidence.contains("outside before T_c = 2 s on 1 of 1"));
        // blf and nac-no-networks were not run.
        assert_eq!(f[3].verdict, Verdict::NotTested);
        assert_eq!(f[4].verdict, Verdict::NotTested);
        assert!(f[2].evidence.contains("vs pd"), "{:?}", f[2]);
    }

    #[test]
    fn without_nac_nothing_is_tested() {
        let f = findings(&run(vec![LawName::Pd]));
        assert!(f.iter().all(|f| f.verdict == Verdict::NotTested));
    }
}
