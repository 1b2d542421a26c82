//! What `testbed sim`, `run` and `replay` print: a JSON object or a table.

use std::fmt::Write;

use crate::analyse::LogAnalysis;
use crate::law_info::LawInfo;
use crate::summary::{ArmMetrics, Summary};
use crate::timing::{Percentiles, TimingSummary};
use scenario::Plan;
use serde::Serialize;

/// The JSON object of `testbed sim|run|replay --json`.
#[derive(Debug, Serialize)]
pub struct Report {
    /// Scenario name.
    pub scenario: String,
    /// Where the scenario came from.
    pub scenario_source: String,
    /// The robot's URDF.
    pub robot: String,
    /// Run length, s.
    pub duration_s: f64,
    /// K1_i per joint.
    pub k1: Vec<f64>,
    /// K2_i per joint.
    pub k2: Vec<f64>,
    /// Joints whose K2_i is at or below the analysis's ½ (SPEC §7 allows it).
    pub k2_below_analysis: Vec<String>,
    /// Joints held still by the scenario (and those that mimic them).
    pub locked_joints: Vec<String>,
    /// Joints coupled by `<mimic>`, not controlled.
    pub mimic_joints: Vec<String>,
    /// What the testbed changed beyond the scenario and URDF files, and
    /// what it warns about (see `scenario::Plan::changes`); empty for a
    /// replayed log.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub changes: Vec<String>,
    /// The control law, whether it is model-based, and its parameters.
    pub law: LawInfo,
    /// The user's command that ran as the controller node (`run
    /// --controller-cmd`): it, not the testbed, computed the torques, with
    /// the scenario's law parameters as its configuration.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller_cmd: Option<String>,
    /// The law that command declared itself to be, and its own parameters
    /// (`key=value` pairs): the law that actually ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller_law: Option<ExternalLaw>,
    /// Controller compute time per step, µs (in process: timed around each
    /// step; a logged run: as the controller node measured it).
    pub compute_us: Percentiles,
    /// The run's figures.
    #[serde(flatten)]
    pub summary: Summary,
    /// Wall-clock time of the loop, s (for a logged run: from the first to
    /// the last joint state's publish time).
    pub wall_time_s: f64,
    /// Sim time per wall time.
    pub realtime_factor: f64,
    /// Timing of a multi-process run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timing: Option<TimingSummary>,
    /// Rows that could not be rebuilt because samples were dropped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub missing_rows: Option<u64>,
    /// Samples the logger could not take (real time), from the log's stats.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub logger_dropped: Option<u64>,
    /// The run's MCAP log.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub log: Option<String>,
    /// The run's folder.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run_dir: Option<String>,
    /// `replay --verify`: largest |τ re-driven − τ logged|.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_abs_torque_diff: Option<f64>,
    /// `replay --verify`: steps compared.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verified_steps: Option<u64>,
    /// Set when the log was read only in part or the run did not finish.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warning: Option<String>,
    /// How a logged run ended ("finished", "interrupted", "lost the plant", …).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run_end: Option<String>,
}

/// The gains and joint roles of a plan, for the report.
struct Gains {
    k1: Vec<f64>,
    k2: Vec<f64>,
    below: Vec<String>,
    locked: Vec<String>,
    mimic: Vec<String>,
}

fn gains(plan: &Plan) -> Gains {
    let m = &plan.robot.model;
    let n = m.dof();
    let c = &plan.scenario.controller;
    // The plan resolved both gains against the arm already.
    let k1 = c.k1.resolve("controller.k1", n).unwrap_or_default();
    let k2 = c.k2.resolve("controller.k2", n).unwrap_or_default();
    let names = m.joint_names();
    Gains {
        below: (0..n)
            .filter(|&i| k2.get(i).is_some_and(|k| *k <= 0.5))
            .map(|i| names[i].clone())
            .collect(),
        k1,
        k2,
        locked: m.locked.iter().map(|l| l.name.clone()).collect(),
        mimic: m
            .mimic
            .iter()
            .map(|c| m.joints[c.joint].name.clone())
            .collect(),
    }
}

impl Report {
    /// For an in-process run; `compute_us` is the controller steps' time.
    pub fn from_sim(
        plan: &Plan,
        summary: Summary,
        wall_time_s: f64,
        compute_us: Percentiles,
    ) -> Self {
        let sim_s = summary.steps as f64 * summary.dt_s;
        let g = gains(plan);
        Self {
            law: LawInfo::of(&plan.scenario.controller),
            compute_us,
            scenario: plan.scenario.name.clone(),
            scenario_source: plan.source.clone(),
            robot: plan.robot.label(),
            duration_s: sim_s,
            k1: g.k1,
            k2: g.k2,
            k2_below_analysis: g.below,
            locked_joints: g.locked,
            changes: plan.changes.clone(),
            mimic_joints: g.mimic,
            realtime_factor: sim_s / wall_time_s.max(1e-9),
            summary,
            wall_time_s,
            timing: None,
            missing_rows: None,
            logger_dropped: None,
            log: None,
            run_dir: None,
            max_abs_torque_diff: None,
            verified_steps: None,
            warning: None,
            run_end: None,
            controller_cmd: None,
            controller_law: None,
        }
    }

    /// For a logged run: everything from the log.
    pub fn from_log(a: LogAnalysis) -> Self {
        let meta = |k: &str| a.contents.run.get(k).cloned().unwrap_or_default();
        let dropped = a.contents.logger_dropped();
        let warning = a.warning();
        let sim_s = a.summary.steps as f64 * a.summary.dt_s;
        let g = gains(&a.plan);
        Self {
            law: LawInfo::of(&a.plan.scenario.controller),
            compute_us: a.timing.controller_compute_us,
            k1: g.k1,
            k2: g.k2,
            k2_below_analysis: g.below,
            locked_joints: g.locked,
            changes: a.plan.changes.clone(),
            mimic_joints: g.mimic,
            scenario: a.plan.scenario.name.clone(),
            scenario_source: meta("scenario_source"),
            robot: meta("robot"),
            duration_s: sim_s,
            realtime_factor: sim_s / a.wall_span_s.max(1e-9),
            wall_time_s: a.wall_span_s,
            timing: Some(a.timing),
            missing_rows: Some(a.missing_rows),
            logger_dropped: dropped,
            log: Some(a.contents.path.display().to_string()),
            run_dir: None,
            max_abs_torque_diff: a.verify.map(|v| v.0),
            verified_steps: a.verify.map(|v| v.1),
            warning,
            run_end: a.contents.run_end().map(String::from),
            controller_cmd: Some(meta("controller_cmd")).filter(|c| !c.is_empty()),
            controller_law: Some(meta("controller_name"))
                .filter(|c| !c.is_empty())
                .map(|name| ExternalLaw {
                    name,
                    parameters: meta("controller_params"),
                    diagnostics: a.own_diagnostics,
                }),
            summary: a.summary,
        }
    }
}

/// An external controller's own law, as it declared it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExternalLaw {
    /// Its name.
    pub name: String,
    /// Its parameters, `key=value` pairs.
    pub parameters: String,
    /// Its own diagnostics over the run: last value and largest magnitude.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub diagnostics: Vec<crate::own::OwnDiagnosticSummary>,
}

fn opt(v: Option<f64>, prec: usize) -> String {
    v.map_or_else(|| "n/a".into(), |x| format!("{x:.prec$}"))
}

/// `p50 … p99 … max …` on one line, µs.
pub fn percentiles(p: &Percentiles) -> String {
    format!("p50 {:8.1}  p99 {:8.1}  max {:8.1}", p.p50, p.p99, p.max)
}

/// A readable summary.
pub fn table(r: &Report) -> String {
    let mut out = String::new();
    heading(&mut out, r);
    joint_table(&mut out, &r.summary);
    verdicts(&mut out, &r.summary);
    metric_lines(&mut out, &r.summary.metrics, &r.compute_us);
    if let Some(t) = &r.timing {
        timing_lines(&mut out, t);
    }
    run_notes(&mut out, r);
    out
}

/// The run, its length, and the gains and joint roles.
fn heading(out: &mut String, r: &Report) {
    let s = &r.summary;
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
    let fmt = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.4}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match (&r.controller_law, &r.controller_cmd) {
        (Some(l), Some(cmd)) => {
            let _ = writeln!(
                out,
                "law {} (external: `{cmd}`; its parameters: {})",
                l.name,
                if l.parameters.is_empty() {
                    "none"
                } else {
                    &l.parameters
                },
            );
        }
        _ => {
            let _ = writeln!(out, "law {}", r.law.label());
        }
    }
    for d in r.controller_law.iter().flat_map(|l| &l.diagnostics) {
        let _ = writeln!(
            out,
            "  its diagnostic {}: last [{}], max |.| [{}]",
            d.name,
            fmt(&d.last),
            fmt(&d.max_abs)
        );
    }
    if let (None, Some(cmd)) = (&r.controller_law, &r.controller_cmd) {
        let _ = writeln!(
            out,
            "controller: `{cmd}` (the user's command computed the torques; the law's \
             parameters were its configuration)"
        );
    }
    let _ = writeln!(out, "gains: K1 = [{}], K2 = [{}]", fmt(&r.k1), fmt(&r.k2));
    if !r.k2_below_analysis.is_empty() {
        let _ = writeln!(
            out,
            "K2 below the analysis's 1/2 (allowed, SPEC §7): {}",
            r.k2_below_analysis.join(", ")
        );
    }
    if !r.locked_joints.is_empty() || !r.mimic_joints.is_empty() {
        let _ = writeln!(
            out,
            "locked joints: [{}]; mimic joints: [{}]",
            r.locked_joints.join(", "),
            r.mimic_joints.join(", ")
        );
    }
    let _ = writeln!(out);
}

fn joint_table(out: &mut String, s: &Summary) {
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
}

fn verdicts(out: &mut String, s: &Summary) {
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
    let e = &s.effects;
    let active = if e.active.is_empty() {
        "none".to_string()
    } else {
        e.active.join(", ")
    };
    let _ = writeln!(
        out,
        "plant effects: {active}; saturated {} steps, commands lost {}, held {}",
        e.saturated_steps, e.dropped_commands, e.held_commands
    );
    if e.contact_steps > 0 {
        let _ = writeln!(
            out,
            "contact: {} steps touched an obstacle",
            e.contact_steps
        );
    }
}

/// BASELINES.md's metrics for the whole arm.
fn metric_lines(out: &mut String, m: &ArmMetrics, compute: &Percentiles) {
    let _ = writeln!(
        out,
        "errors after T_c (sums over joints): IAE {}, ISE {}, ITAE {}; RMS {}",
        opt(m.iae_after_tc, 5),
        opt(m.ise_after_tc, 6),
        opt(m.itae_after_tc, 4),
        opt(m.rms_error_after_tc, 5)
    );
    let entered = m.entered_envelope_s.map_or_else(
        || "never (outside at the end)".into(),
        |t| format!("{t:.3} s"),
    );
    let _ = writeln!(
        out,
        "envelope: inside for good from {entered}; violated {:.3} s ({:.3} s after T_c)",
        m.violation_s, m.violation_after_tc_s
    );
    let _ = writeln!(
        out,
        "effort: int tau^2 {:.3} ({:.3} after T_c{}), torque rate int dtau^2 {:.1}, spectral \
         smoothness {}, peak |tau| {:.2}, saturated {:.3} s; breaches {}",
        m.effort,
        m.effort_after_tc,
        m.effort_beyond_gravity_after_tc
            .map_or_else(String::new, |e| format!("; {e:.3} beyond the gravity hold")),
        m.torque_rate,
        opt(m.torque_smoothness, 4),
        m.peak_abs_torque,
        m.saturated_s,
        m.breaches
    );
    let _ = writeln!(
        out,
        "actor: peak |tau_actor| {:.4}, int tau_actor^2 {:.4}; controller compute per step: \
         p50 {:.2} us, p99 {:.2} us",
        m.peak_actor_torque, m.actor_effort, compute.p50, compute.p99
    );
}

fn timing_lines(out: &mut String, t: &TimingSummary) {
    let stale = t
        .stale_references
        .map_or_else(|| "n/a".to_string(), |n| n.to_string());
    let _ = writeln!(
        out,
        "\ntiming ({} at {} Hz): verdict {}; {} cycles, {} deadline misses, {stale} stale \
         references, {} wake-ups late by a period",
        t.mode.as_str(),
        t.rate_hz,
        t.verdict.as_str().to_uppercase(),
        t.cycles,
        t.deadline_misses,
        t.late_wakeups
    );
    for reason in &t.reasons {
        let _ = writeln!(out, "  - {reason}");
    }
    if let Some(f) = t.floor_late_wakeups {
        let _ = writeln!(
            out,
            "  timer floor beside the plant: {f} wake-ups late by a period"
        );
    }
    if let Some(n) = t.timing_faults_before_non_finite {
        let _ = writeln!(
            out,
            "  timing faults (misses, stale references) up to the first non-finite step: {n}"
        );
    }
    let mut row = |name: &str, p: &Percentiles| {
        let _ = writeln!(out, "  {name:<17} {}", percentiles(p));
    };
    row("period jitter us", &t.period_jitter_us);
    row("wake late us", &t.wake_late_us);
    row("round trip us", &t.round_trip_us);
    row("controller us", &t.controller_compute_us);
    if let Some(d) = &t.data_path {
        row("state age us", &d.state_age_us);
        row("command age us", &d.command_age_us);
        if d.reference_lag_us.count > 0 {
            row("ref. lag us", &d.reference_lag_us);
        }
    }
}

fn run_notes(out: &mut String, r: &Report) {
    if let Some(m) = r.missing_rows.filter(|m| *m > 0) {
        let _ = writeln!(out, "rows lost to dropped samples: {m}");
    }
    if let Some(d) = r.logger_dropped.filter(|d| *d > 0) {
        let _ = writeln!(out, "samples the logger could not take: {d}");
    }
    if let (Some(d), Some(n)) = (r.max_abs_torque_diff, r.verified_steps) {
        let _ = writeln!(
            out,
            "verify: {n} steps re-driven, max |tau - logged tau| = {d:e}"
        );
    }
    if let Some(l) = &r.log {
        let _ = writeln!(out, "log: {l}");
    }
}
