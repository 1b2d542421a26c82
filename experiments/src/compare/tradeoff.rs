//! `compare --gain-scales`: every law over a range of gain scales, as
//! tracking error (IAE after T_c) against effort beyond the gravity hold
//! (∫(τ − G(q))² after T_c; ∫τ² is mostly that hold) and
//! against mechanical energy (∫|τ q̇| after T_c), so that a reader sees each
//! law's whole trade-off, not one tuning's point.
//!
//! A scale s multiplies K1 and K2 on every joint; each law then derives its
//! own gains from them by the comparison's tuning rule.

use controller::Gain;
use scenario::Plan;
use serde::Serialize;

use crate::compare::{self, CompareError, CompareOptions, Comparison};

/// One law at one scale (medians over seeds).
#[derive(Debug, Clone, Serialize)]
pub struct TradeoffPoint {
    /// The law.
    pub law: controller::LawName,
    /// K1 and K2 times this.
    pub scale: f64,
    /// Median IAE after T_c (sum over joints), rad s; null if failed.
    pub iae: Option<f64>,
    /// Median effort beyond the gravity hold, ∫(τ − G(q))² dt after T_c,
    /// N² m² s; null if failed.
    pub effort: Option<f64>,
    /// Median raw effort ∫τ² dt after T_c, N² m² s; null if failed.
    pub effort_raw: Option<f64>,
    /// Median time some torque was clipped at its limit, s: a point
    /// with saturation is limited by the motors, not by its gains.
    pub saturated_s: f64,
    /// Median mechanical energy ∫|τ q̇| dt after T_c, J; null if failed.
    pub energy: Option<f64>,
    /// Seeds whose run failed.
    pub failed: u64,
    /// Not dominated by another scale of the same law (no other point has
    /// both less IAE and less effort).
    pub on_front: bool,
    /// The same with energy in place of effort.
    pub on_energy_front: bool,
}

/// Every law at every scale.
#[derive(Debug, Clone, Serialize)]
pub struct Tradeoff {
    /// The scales, in the order run.
    pub scales: Vec<f64>,
    /// One point per law and scale, law by law.
    pub points: Vec<TradeoffPoint>,
    /// The comparison at each scale.
    #[serde(skip)]
    pub comparisons: Vec<Comparison>,
}

/// Why a trade-off cannot be run.
#[derive(Debug, thiserror::Error)]
pub enum TradeoffError {
    /// A scale that is not a positive finite number.
    #[error("--gain-scales {0}: every scale must be a finite number > 0")]
    Scale(f64),
    /// A comparison failed.
    #[error("at gain scale {scale}: {cause}")]
    Compare {
        /// The scale.
        scale: f64,
        /// The cause.
        cause: Box<CompareError>,
    },
}

/// `plan` with K1 and K2 times `s`.
pub fn scaled(plan: &Plan, s: f64) -> Plan {
    let mut p = plan.clone();
    for c in [&mut p.undrawn.controller, &mut p.scenario.controller] {
        c.k1 = times(&c.k1, s);
        c.k2 = times(&c.k2, s);
    }
    p
}

fn times(g: &Gain, s: f64) -> Gain {
    match g {
        Gain::All(x) => Gain::All(x * s),
        Gain::Each(v) => Gain::Each(v.iter().map(|x| x * s).collect()),
    }
}

/// Runs the comparison at every scale of `scales`.
pub fn tradeoff(
    plan: &Plan,
    opts: &CompareOptions,
    scales: &[f64],
) -> Result<Tradeoff, TradeoffError> {
    if let Some(&bad) = scales.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(TradeoffError::Scale(bad));
    }
    let comparisons = scales
        .iter()
        .map(|&scale| {
            compare::compare(&scaled(plan, scale), opts).map_err(|cause| TradeoffError::Compare {
                scale,
                cause: Box::new(cause),
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut points = Vec::new();
    for (k, &law) in opts.laws.iter().enumerate() {
        let mine: Vec<TradeoffPoint> = scales
            .iter()
            .zip(&comparisons)
            .map(|(&scale, c)| point(law, scale, &c.laws[k]))
            .collect();
        points.extend(mark_front(mine));
    }
    Ok(Tradeoff {
        scales: scales.to_vec(),
        points,
        comparisons,
    })
}

fn point(law: controller::LawName, scale: f64, row: &compare::LawRow) -> TradeoffPoint {
    let finite = |x: Option<f64>| x.filter(|v| v.is_finite());
    TradeoffPoint {
        law,
        scale,
        iae: finite(row.median.get("iae")),
        effort: finite(row.median.get("effort_beyond_gravity")),
        effort_raw: finite(row.median.get("effort_after_tc")),
        saturated_s: row.median.get("saturated_s").unwrap_or(f64::NAN),
        energy: finite(row.median.get("energy_after_tc")),
        failed: row.runs.iter().filter(|r| r.failed.is_some()).count() as u64,
        on_front: false,
        on_energy_front: false,
    }
}

/// Marks the points no other point of the same law dominates, on effort
/// and on energy.
fn mark_front(mut points: Vec<TradeoffPoint>) -> Vec<TradeoffPoint> {
    let effort = front(points.iter().map(|p| p.iae.zip(p.effort)).collect());
    let energy = front(points.iter().map(|p| p.iae.zip(p.energy)).collect());
    for (p, (a, b)) in points.iter_mut().zip(effort.into_iter().zip(energy)) {
        p.on_front = a;
        p.on_energy_front = b;
    }
    points
}

/// For each (error, cost) pair: whether no other pair is at least as good
/// on both and better on one (a missing pair is never on the front).
fn front(pairs: Vec<Option<(f64, f64)>>) -> Vec<bool> {
    pairs
        .iter()
        .map(|p| {
            p.is_some_and(|(a, e)| {
                !pairs
                    .iter()
                    .flatten()
                    .any(|&(b, f)| b <= a && f <= e && (b < a || f < e))
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(iae: f64, effort: f64) -> TradeoffPoint {
        TradeoffPoint {
            law: controller::LawName::Pd,
            scale: 1.0,
            iae: Some(iae),
            effort: Some(effort),
            effort_raw: Some(effort),
            saturated_s: 0.0,
            energy: Some(1.0 / effort),
            failed: 0,
            on_front: false,
            on_energy_front: false,
        }
    }

    #[test]
    fn the_front_keeps_the_undominated_points() {
        let mut failed = p(0.0, 0.0);
        failed.iae = None;
        let marked = mark_front(vec![p(1.0, 5.0), p(2.0, 2.0), p(3.0, 3.0), failed]);
        let on = |f: fn(&TradeoffPoint) -> bool| marked.iter().map(f).collect::<Vec<_>>();
        assert_eq!(on(|p| p.on_front), [true, true, false, false]);
        // Energy 1/effort: (1, 0.2), (2, 0.5), (3, 0.33): only the first.
        assert_eq!(on(|p| p.on_energy_front), [true, false, false, false]);
    }

    #[test]
    fn a_scale_multiplies_both_gains() {
        let plan = scenario::load(None, &scenario::Overrides::default()).unwrap();
        let s = scaled(&plan, 2.0);
        assert_eq!(s.undrawn.controller.k1, Gain::All(30.0));
        assert_eq!(s.scenario.controller.k2, Gain::All(30.0));
        let opts = CompareOptions {
            law_sets: Vec::new(),
            external: Vec::new(),
            runs_dir: std::path::PathBuf::from("runs"),
            progress: false,
            laws: vec![controller::LawName::Pd],
            seeds: 1,
            threads: Some(1),
            series: false,
            tuning: None,
        };
        assert!(matches!(
            tradeoff(&plan, &opts, &[1.0, -1.0]),
            Err(TradeoffError::Scale(-1.0))
        ));
    }
}
