//! What `testbed sim` prints: a JSON object or a table.

use std::fmt::Write;

use launch::run::timing::{Percentiles, TimingSummary};
use launch::summary::Summary;
use scenario::Plan;
use serde::Serialize;

/// The JSON object of `testbed sim --json`.
#[derive(Debug, Serialize)]
pub struct SimReport {
    /// Scenario name.
    pub scenario: String,
    /// Where the scenario came from.
    pub scenario_source: String,
    /// The robot's URDF.
    pub robot: String,
    /// Run length, s.
    pub duration_s: f64,
    /// The run's figures.
    #[serde(flatten)]
    pub summary: Summary,
    /// Wall-clock time of the loop, s.
    pub wall_time_s: f64,
    /// Sim time per wall time.
    pub realtime_factor: f64,
    /// Timing of a multi-process run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timing: Option<TimingSummary>,
    /// The run's folder (multi-process runs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run_dir: Option<String>,
    /// Rows that could not be rebuilt because samples were dropped (multi-process runs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub missing_rows: Option<u64>,
}

impl SimReport {
    pub fn new(plan: &Plan, summary: Summary, wall_time_s: f64) -> Self {
        let sim_s = summary.steps as f64 * summary.dt_s;
        Self {
            scenario: plan.scenario.name.clone(),
            scenario_source: plan.source.clone(),
            robot: plan.robot.label(),
            duration_s: sim_s,
            realtime_factor: sim_s / wall_time_s.max(1e-9),
            summary,
            wall_time_s,
            timing: None,
            run_dir: None,
            missing_rows: None,
        }
    }
}

fn percentiles(p: &Percentiles) -> String {
    format!("p50 {:8.1}  p99 {:8.1}  max {:8.1}", p.p50, p.p99, p.max)
}

fn opt(v: Option<f64>, prec: usize) -> String {
    v.map_or_else(|| "n/a".into(), |x| format!("{x:.prec$}"))
}

/// A readable summary.
pub fn table(r: &SimReport) -> String {
    let s = &r.summary;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "scenario {} ({}), robot {}, {} joints",
        r.scenario, r.scenario_source, r.robot, s.dof
    );
    let _ = writeln!(
        out,
        "{} steps of {} ms = {} s sim time, T_c = {} s; wall time {:.3} s ({:.1}x real time)\n",
        s.steps,
        s.dt_s * 1e3,
        r.duration_s,
        s.tc_s,
        r.wall_time_s,
        r.realtime_factor
    );
    let _ = writeln!(
        out,
        "{:<12} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12} {:>10} {:>10}",
        "joint",
        "max|Z1|>=Tc",
        "minmargin",
        "rmsZ1>=Tc",
        "max|Z1g|/kc",
        "int tau^2",
        "..>=Tc",
        "max|tau|",
        "max|Wa|"
    );
    for j in &s.joints {
        let _ = writeln!(
            out,
            "{:<12} {:>12} {:>12} {:>12} {:>12.4} {:>12.3} {:>12.3} {:>10.2} {:>10.4}",
            j.name,
            opt(j.max_abs_error_after_tc, 5),
            opt(j.min_margin_after_tc, 5),
            opt(j.rms_error_after_tc, 5),
            j.max_gamma_error_ratio,
            j.effort_integral,
            j.effort_integral_after_tc,
            j.max_abs_torque,
            j.max_actor_weight_norm
        );
    }
    let ends_before_tc = s.joints.iter().all(|j| j.min_margin_after_tc.is_none());
    let verdict = if ends_before_tc {
        "not judged (the run ends before T_c)"
    } else if s.constraint_satisfied_after_tc {
        "satisfied"
    } else {
        "VIOLATED"
    };
    let _ = writeln!(out, "\nconstraint |Z1| < k_c for t >= T_c: {verdict}");
    let _ = writeln!(
        out,
        "barrier breaches: {} steps; controller faults: {} steps; all signals finite: {}",
        s.barrier_breached_steps,
        s.fault_steps,
        if s.finite { "yes" } else { "NO" }
    );
    if let Some(t) = &r.timing {
        let _ = writeln!(
            out,
            "\ntiming ({} at {} Hz): {} cycles, {} deadline misses",
            t.mode.as_str(),
            t.rate_hz,
            t.cycles,
            t.deadline_misses
        );
        let _ = writeln!(
            out,
            "  period jitter us  {}",
            percentiles(&t.period_jitter_us)
        );
        let _ = writeln!(out, "  wake late us      {}", percentiles(&t.wake_late_us));
        let _ = writeln!(out, "  round trip us     {}", percentiles(&t.round_trip_us));
        let _ = writeln!(
            out,
            "  controller us     {}",
            percentiles(&t.controller_compute_us)
        );
    }
    if let Some(m) = r.missing_rows.filter(|m| *m > 0) {
        let _ = writeln!(out, "rows lost to dropped samples: {m}");
    }
    if let Some(d) = &r.run_dir {
        let _ = writeln!(out, "run folder: {d}");
    }
    out
}
