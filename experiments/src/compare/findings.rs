//! What a comparison says about the paper's claims, with the numbers, by
//! stated rules (so that a reader can check each verdict). The facts they
//! rest on are the same for every law ([`crate::compare::scores`]): a run
//! *failed* when it could not be scored (stopped, non-finite, faults); it
//! *kept* the envelope when |e| < k_c at every t ≥ T_c, *left* it
//! otherwise, and is *not judged* when it ended before T_c.
//!
//! 1. *Inside the envelope after T_c*: holds when every `nac` run was
//!    judged, kept the envelope and did not fail; not judged when no run
//!    reached T_c. The evidence counts every other law's runs by the same
//!    rule.
//! 2. *Starting outside*: tested when some `nac` run was outside the
//!    envelope before T_c; holds when every such run was inside for good by
//!    T_c and did not fail.
//! 3. *Keeping it where another law does not* (against each law without a
//!    barrier that runs: `pd`, `pd-gravity`, `ctc`; and, as its own claim,
//!    against the baselines a reviewer asks for: `smc`, and the
//!    constrained model-based `cbf-ctc` and `mpc`), seed by seed: holds
//!    when on some seed `nac` kept the envelope and the other left it, and
//!    on none the reverse; does not hold when on some seed the other kept it
//!    and `nac` left it; not tested when no seed separates them.
//! 4. *Effort after T_c*: `nac`'s median effort beyond the gravity hold,
//!    ∫(τ − G(q))², against `pd`'s and `blf`'s, and its mechanical energy
//!    ∫|τ q̇| against `pd`'s; *what the actor–critic adds*: `nac` against
//!    `nac-no-networks` on IAE after T_c. Each holds when `nac` is lower by
//!    at least [`MATTERS`] (or the other's median failed and `nac`'s did
//!    not) and, over two or more seeds that differ, the paired test agrees
//!    (Holm-corrected p < [`ALPHA`], `nac` better on more seeds). With one
//!    seed of a scenario with random effects these are not tested: one draw
//!    says nothing about a difference.
//!
//! A claim whose law is not in the comparison is "not tested".

use controller::LawName;

use crate::compare::types::{Comparison, Envelope, Finding, LawRow, Paired, Verdict};

/// A relative difference smaller than this is "no difference".
pub const MATTERS: f64 = 0.01;
/// The paired test's level (on Holm-corrected p-values).
pub const ALPHA: f64 = 0.05;

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
    let mut out = vec![inside(c, nac), outside(c, nac)];
    for other in [LawName::Pd, LawName::PdGravity, LawName::Ctc] {
        out.push(separates(c, nac, other, CLAIMS[2]));
    }
    for other in [LawName::Pd, LawName::Blf] {
        out.push(better(c, nac, other, "effort_beyond_gravity", CLAIMS[3]));
    }
    out.push(better(c, nac, LawName::Pd, "energy_after_tc", CLAIMS[3]));
    out.push(better(c, nac, LawName::NacNoNetworks, "iae", CLAIMS[4]));
    for other in [LawName::Smc, LawName::CbfCtc, LawName::Mpc] {
        out.push(separates(c, nac, other, CLAIMS[5]));
    }
    out
}

const CLAIMS: [&str; 6] = [
    "nac keeps |e| < k_c after T_c",
    "nac may start outside the envelope and is inside by T_c",
    "nac keeps the envelope on seeds where a law without a barrier leaves it",
    "nac uses less effort after T_c",
    "the actor-critic lowers the error after T_c",
    "nac keeps the envelope on seeds where a reviewer's baseline leaves it",
];

fn row(c: &Comparison, law: LawName) -> Option<&LawRow> {
    c.laws
        .iter()
        .find(|r| r.law.law == law && r.external.is_none())
}

/// "kept K, left L, not judged J, failed F of N".
fn counts(r: &LawRow) -> String {
    format!(
        "kept {}, left {}, not judged {}, failed {} of {}",
        r.kept_envelope,
        r.left_envelope,
        r.not_judged,
        r.failed,
        r.runs.len()
    )
}

fn inside(c: &Comparison, nac: &LawRow) -> Finding {
    let n = nac.runs.len() as u64;
    let verdict = if nac.not_judged == n {
        Verdict::NotJudged
    } else if nac.kept_envelope == n && nac.failed == 0 {
        Verdict::Holds
    } else {
        Verdict::DoesNotHold
    };
    let others: Vec<String> = c
        .laws
        .iter()
        .filter(|r| !std::ptr::eq(*r, nac))
        .map(|r| format!("{}: {}", r.name, counts(r)))
        .collect();
    let margin = if nac.kept_envelope + nac.left_envelope > 0 {
        format!(
            "; median min margin k_c - |e| after T_c {}, median max |e| {}",
            num(nac.median.get("min_margin")),
            num(nac.median.get("max_abs_error")),
        )
    } else {
        format!("; every run ended before T_c = {} s", tc(nac))
    };
    let others = if others.is_empty() {
        String::new()
    } else {
        format!("; by the same rule, {}", others.join("; "))
    };
    Finding {
        claim: CLAIMS[0].into(),
        verdict,
        evidence: format!("nac: {}{margin}{others}", counts(nac)),
    }
}

fn tc(r: &LawRow) -> f64 {
    r.runs.first().map_or(f64::NAN, |x| x.summary.tc_s)
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
    let tc = tc(nac);
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
        let mut breaches: Vec<u64> = r
            .runs
            .iter()
            .map(|x| x.summary.barrier_breached_steps)
            .collect();
        breaches.sort_unstable();
        format!(
            "; with the constraint on from t = 0 (nac-no-shift): median {} barrier breaches, {}",
            breaches.get(breaches.len() / 2).copied().unwrap_or(0),
            counts(r)
        )
    });
    let verdict = match (early.len(), entered == early.len()) {
        _ if nac.not_judged == nac.runs.len() as u64 => Verdict::NotJudged,
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

/// `nac` against `other`, seed by seed, on keeping the envelope (claim 3).
fn separates(c: &Comparison, nac: &LawRow, other: LawName, claim: &str) -> Finding {
    let claim = format!("{claim} (vs {other})");
    let Some(o) = row(c, other) else {
        return Finding {
            claim,
            verdict: Verdict::NotTested,
            evidence: format!("{other} is not in the comparison"),
        };
    };
    let pairs = nac.runs.iter().zip(&o.runs);
    let nac_only = pairs
        .clone()
        .filter(|(a, b)| a.envelope == Envelope::Kept && b.envelope == Envelope::Left)
        .count();
    let other_only = pairs
        .filter(|(a, b)| a.envelope == Envelope::Left && b.envelope == Envelope::Kept)
        .count();
    let verdict = match (nac_only, other_only) {
        _ if nac.not_judged == nac.runs.len() as u64 => Verdict::NotJudged,
        (_, 1..) => Verdict::DoesNotHold,
        (1.., 0) => Verdict::Holds,
        (0, 0) => Verdict::NotTested,
    };
    Finding {
        claim,
        verdict,
        evidence: format!(
            "nac kept it and {other} left it on {nac_only} seeds, the reverse on {other_only}; nac: {}; {other}: {}",
            counts(nac),
            counts(o)
        ),
    }
}

/// `nac` against `other` on `metric` (smaller is better), by the rule of
/// the module's claim 4.
fn better(c: &Comparison, nac: &LawRow, other: LawName, metric: &str, claim: &str) -> Finding {
    let claim = format!("{claim} (vs {other}, {metric})");
    let Some(o) = row(c, other) else {
        return Finding {
            claim,
            verdict: Verdict::NotTested,
            evidence: format!("{other} is not in the comparison"),
        };
    };
    if nac.not_judged == nac.runs.len() as u64 {
        return Finding {
            claim,
            verdict: Verdict::NotJudged,
            evidence: format!("every run ended before T_c = {} s", tc(nac)),
        };
    }
    let (a, b) = (
        nac.median.get(metric).unwrap_or(f64::NAN),
        o.median.get(metric).unwrap_or(f64::NAN),
    );
    let rel = (a - b) / b.abs();
    let medians = format!(
        "median nac {} vs {other} {} ({})",
        num(Some(a)),
        num(Some(b)),
        if rel.is_finite() {
            format!("{:+.2} %", 100.0 * rel)
        } else {
            "a failed median".into()
        }
    );
    let raw = if metric == "effort_beyond_gravity" {
        format!(
            "; raw ∫τ² after T_c: nac {} vs {other} {}",
            num(nac.median.get("effort_after_tc")),
            num(o.median.get("effort_after_tc"))
        )
    } else {
        String::new()
    };
    if c.seeds == 1 && !c.random_effects.is_empty() {
        return Finding {
            claim,
            verdict: Verdict::NotTested,
            evidence: format!(
                "{medians}{raw}; one draw of random effects ({}): no difference is reported from one seed",
                c.random_effects.join(", ")
            ),
        };
    }
    let test = paired(c, other, metric);
    let agrees = test.is_none_or(|p| p.p_holm < ALPHA && p.test.a_smaller > p.test.b_smaller);
    // A failed median is the worst value: below it is lower.
    let lower = a.is_finite() && (!b.is_finite() || rel <= -MATTERS);
    let verdict = match (lower && agrees, a.is_finite() || b.is_finite()) {
        (true, _) => Verdict::Holds,
        (false, true) => Verdict::DoesNotHold,
        (false, false) => Verdict::NotTested,
    };
    let p = match test {
        Some(p) => format!(
            "nac better on {} of {} seeds, worse on {}, Wilcoxon p = {:.2e} (Holm {:.2e})",
            p.test.a_smaller, p.test.pairs, p.test.b_smaller, p.test.p_value, p.p_holm
        ),
        None if c.seeds > 1 => format!(
            "{} identical seeds (nothing random): one run, no paired test",
            c.seeds
        ),
        None => "one seed, no paired test".into(),
    };
    Finding {
        claim,
        verdict,
        evidence: format!("{medians}{raw}; {p}"),
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
        run_for(4.0, laws)
    }

    /// The paper scenario for `duration` s, one seed, `laws`.
    fn run_for(duration: f64, laws: Vec<LawName>) -> Comparison {
        let plan = scenario::load(
            None,
            &scenario::Overrides {
                duration_s: Some(duration),
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
        assert_eq!(f.len(), 12);
        assert!(f[7].claim.contains("energy_after_tc"), "{:?}", f[7]);
        assert_eq!(f[0].verdict, Verdict::Holds, "{:?}", f[0]);
        assert!(f[0].evidence.contains("pd: kept 1, left 0"), "{:?}", f[0]);
        assert_eq!(f[1].verdict, Verdict::Holds, "{:?}", f[1]);
        assert!(f[1].evidence.contains("outside before T_c = 2 s on 1 of 1"));
        // Both keep it: no seed separates them.
        assert_eq!(f[2].verdict, Verdict::NotTested, "{:?}", f[2]);
        // pd-gravity, ctc, blf, nac-no-networks, smc, cbf-ctc and mpc
        // were not run.
        for k in [3, 4, 6, 8, 9, 10, 11] {
            assert_eq!(f[k].verdict, Verdict::NotTested, "{:?}", f[k]);
        }
        assert!(f[5].evidence.contains("vs pd"), "{:?}", f[5]);
        assert!(f[5].evidence.contains("raw ∫τ² after T_c"), "{:?}", f[5]);
    }

    #[test]
    fn runs_shorter_than_tc_are_not_judged() {
        let f = findings(&run_for(1.0, vec![LawName::Nac, LawName::Pd]));
        for k in [0, 1, 2, 5, 7] {
            assert_eq!(f[k].verdict, Verdict::NotJudged, "{:?}", f[k]);
        }
    }

    #[test]
    fn without_nac_nothing_is_tested() {
        let f = findings(&run(vec![LawName::Pd]));
        assert!(f.iter().all(|f| f.verdict == Verdict::NotTested));
    }
}
