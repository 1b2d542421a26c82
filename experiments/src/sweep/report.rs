//! `testbed sweep report`: per cell (axis values × law), the median,
//! interquartile range and worst of every metric across seeds, and the
//! success rate, from a results folder alone.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use super::SweepError;
use super::results::{ResultLine, read_manifest, read_results};
use crate::compare::METRICS;

/// One metric of one cell across its seeds (±∞ where a run lacks the
/// value: it counts as the worst; JSON null).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MetricStats {
    /// The metric (as in `compare`).
    pub metric: &'static str,
    /// Median.
    #[serde(serialize_with = "finite_or_null")]
    pub median: f64,
    /// 25th percentile (linear interpolation).
    #[serde(serialize_with = "finite_or_null")]
    pub q1: f64,
    /// 75th percentile.
    #[serde(serialize_with = "finite_or_null")]
    pub q3: f64,
    /// The worst seed's value.
    #[serde(serialize_with = "finite_or_null")]
    pub worst: f64,
    /// Every seed's value, sorted (for box plots).
    #[serde(skip)]
    pub values: Vec<f64>,
}

fn finite_or_null<S: serde::Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    if v.is_finite() {
        s.serialize_f64(*v)
    } else {
        s.serialize_none()
    }
}

/// One cell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellReport {
    /// Axis values.
    pub cell: serde_json::Map<String, serde_json::Value>,
    /// The law.
    pub law: String,
    /// Runs of the cell in the sweep.
    pub runs: usize,
    /// Of those, with a result.
    pub found: usize,
    /// Results that failed or diverged.
    pub not_ok: usize,
    /// Share of the found runs that kept the envelope after T_c, finite.
    /// (None: no run reached T_c, so none is judged.)
    pub success_rate: Option<f64>,
    /// Every metric.
    pub metrics: Vec<MetricStats>,
}

/// The whole report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepReport {
    /// The sweep's name.
    pub name: String,
    /// Axis keys.
    pub axes: Vec<String>,
    /// Runs in the sweep.
    pub total_runs: usize,
    /// Runs with a result.
    pub found_runs: usize,
    /// Lines that could not be read (cut short by a kill).
    pub unreadable_lines: usize,
    /// One entry per cell, in sweep order.
    pub cells: Vec<CellReport>,
}

/// A cell's values and its runs' results (None: not done yet).
type Group<'a> = (
    serde_json::Map<String, serde_json::Value>,
    Vec<Option<&'a ResultLine>>,
);

/// Reads the folder `dir` and aggregates it.
pub fn report(dir: &Path) -> Result<SweepReport, SweepError> {
    let manifest = read_manifest(dir)?;
    let (results, bad) = read_results(dir)?;
    // Cells in the order of their first run.
    let mut order: Vec<(String, String)> = Vec::new();
    let mut groups: BTreeMap<(String, String), Group<'_>> = BTreeMap::new();
    for run in &manifest.runs {
        let id = (
            serde_json::Value::Object(run.cell.clone()).to_string(),
            run.law.to_string(),
        );
        let entry = groups.entry(id.clone()).or_insert_with(|| {
            order.push(id.clone());
            (run.cell.clone(), Vec::new())
        });
        entry.1.push(results.get(&run.key));
    }
    let cells: Vec<CellReport> = order
        .iter()
        .filter_map(|id| {
            let (cell, lines) = groups.get(id)?;
            Some(cell_report(cell.clone(), id.1.clone(), lines))
        })
        .collect();
    Ok(SweepReport {
        name: manifest.name,
        axes: manifest.axes,
        total_runs: manifest.runs.len(),
        found_runs: cells.iter().map(|c| c.found).sum(),
        unreadable_lines: bad,
        cells,
    })
}

/// Whether a run counts toward the success rate: it failed, or it reached
/// T_c (a run that ends before T_c says nothing about the constraint).
fn is_judged(l: &ResultLine) -> bool {
    l.status != "ok"
        || l.summary["joints"]
            .as_array()
            .is_some_and(|j| j.iter().any(|x| !x["min_margin_after_tc"].is_null()))
}

fn cell_report(
    cell: serde_json::Map<String, serde_json::Value>,
    law: String,
    lines: &[Option<&ResultLine>],
) -> CellReport {
    let found: Vec<&ResultLine> = lines.iter().flatten().copied().collect();
    let kept = found.iter().filter(|l| l.kept_envelope).count();
    let metrics = METRICS
        .iter()
        .map(|m| {
            let worst_value = if m.larger_is_worse {
                f64::INFINITY
            } else {
                f64::NEG_INFINITY
            };
            let mut v: Vec<f64> = found
                .iter()
                .map(|l| {
                    l.metrics
                        .get(m.name)
                        .and_then(|x| x.as_f64())
                        .unwrap_or(worst_value)
                })
                .collect();
            v.sort_by(f64::total_cmp);
            let worst = match (m.larger_is_worse, v.first(), v.last()) {
                (true, _, Some(w)) | (false, Some(w), _) => *w,
                _ => f64::NAN,
            };
            MetricStats {
                metric: m.name,
                median: quantile(&v, 0.5),
                q1: quantile(&v, 0.25),
                q3: quantile(&v, 0.75),
                worst,
                values: v,
            }
        })
        .collect();
    CellReport {
        cell,
        law,
        runs: lines.len(),
        found: found.len(),
        not_ok: found.iter().filter(|l| l.status != "ok").count(),
        success_rate: {
            let judged = found.iter().filter(|l| is_judged(l)).count();
            (judged > 0).then(|| kept as f64 / judged as f64)
        },
        metrics,
    }
}

pub use analysis::stats::quantile;

/// The report as CSV: one row per cell; axis columns, `law`, `runs`,
/// `found`, `success_rate`, then `<metric>_median,_q1,_q3,_worst`.
pub fn csv(r: &SweepReport) -> String {
    let mut head: Vec<String> = r.axes.clone();
    head.extend(["law", "runs", "found", "success_rate"].map(String::from));
    for m in METRICS {
        for s in ["median", "q1", "q3", "worst"] {
            head.push(format!("{}_{s}", m.name));
        }
    }
    let mut out = head.join(",") + "\n";
    let num = |x: f64| {
        if x.is_finite() {
            format!("{x:?}")
        } else {
            String::new()
        }
    };
    for c in &r.cells {
        let mut row: Vec<String> = r
            .axes
            .iter()
            .map(|a| c.cell.get(a).map_or_else(String::new, |v| v.to_string()))
            .collect();
        row.extend([
            c.law.clone(),
            c.runs.to_string(),
            c.found.to_string(),
            c.success_rate.map_or_else(String::new, num),
        ]);
        for m in &c.metrics {
            row.extend([num(m.median), num(m.q1), num(m.q3), num(m.worst)]);
        }
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

/// A readable table: one line per cell with the headline metrics.
pub fn table(r: &SweepReport) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "sweep {}: {} of {} runs found{}",
        r.name,
        r.found_runs,
        r.total_runs,
        if r.unreadable_lines > 0 {
            format!(", {} unreadable lines ignored", r.unreadable_lines)
        } else {
            String::new()
        }
    );
    let _ = writeln!(
        out,
        "{:<40} {:<14} {:>6} {:>8}  {:>28}  {:>20}  {:>10}",
        "cell",
        "law",
        "runs",
        "success",
        "IAE median [q1, q3] worst",
        "max|e| median worst",
        "eff>Tc med"
    );
    for c in &r.cells {
        let cell: Vec<String> = c.cell.iter().map(|(k, v)| format!("{k}={v}")).collect();
        let get = |name: &str| c.metrics.iter().find(|m| m.metric == name);
        let f = |x: f64| {
            if x.is_finite() {
                format!("{x:.4}")
            } else {
                "n/a".into()
            }
        };
        let iae = get("iae").map_or_else(String::new, |m| {
            format!("{} [{}, {}] {}", f(m.median), f(m.q1), f(m.q3), f(m.worst))
        });
        let maxe = get("max_abs_error")
            .map_or_else(String::new, |m| format!("{} {}", f(m.median), f(m.worst)));
        let eff = get("effort_after_tc").map_or_else(String::new, |m| f(m.median));
        let _ = writeln!(
            out,
            "{:<40} {:<14} {:>6} {:>8}  {:>28}  {:>20}  {:>10}",
            cell.join(" "),
            c.law,
            format!("{}/{}", c.found, c.runs),
            c.success_rate
                .map_or_else(|| "not judged".into(), |r| format!("{:.0}%", 100.0 * r)),
            iae,
            maxe,
            eff
        );
    }
    out
}
