//! `testbed compare`: the laws side by side on one scenario.

use std::fmt::Write as _;
use std::io::Write as _;
use std::process::ExitCode;

use std::io::IsTerminal;

use anyhow::{Context, Result, bail};
use experiments::compare::{self, CompareOptions, Comparison, METRICS};

use super::args::{CompareArgs, ScenarioArgs};

pub(crate) fn compare(args: CompareArgs) -> Result<ExitCode> {
    if args.seeds == 0 {
        bail!("--seeds 0: compare needs at least one seed");
    }
    // Checked before anything is allocated: each run keeps its summary
    // (and its series with --plots).
    if args.seeds > compare::MAX_SEEDS {
        bail!(
            "--seeds {}: at most {} seeds per law (use a sweep for more)",
            args.seeds,
            compare::MAX_SEEDS
        );
    }
    if args.threads == Some(0) {
        bail!("--threads 0: compare needs at least one thread");
    }
    let common = ScenarioArgs {
        scenario: args.scenario.clone(),
        robot: args.robot.clone(),
        duration: args.duration,
        law: None,
        json: args.json,
        csv: None,
        set: args.set.clone(),
    };
    let plan = super::load(&common, None)?;
    // Refuse an unwritable CSV, or one that is an input, before the runs.
    let csv = match &args.csv {
        Some(path) => {
            let inputs = super::outputs::plan_inputs(args.scenario.as_deref(), &plan);
            super::outputs::refuse_input("--csv", path, &inputs)?;
            Some((
                path,
                std::fs::File::create(path)
                    .with_context(|| format!("cannot create CSV file {}", path.display()))?,
            ))
        }
        None => None,
    };
    if args.controller_cmd.is_empty() {
        super::no_external(&plan, "compare")?;
    }
    let laws = if args.laws.is_empty() {
        compare::DEFAULT_LAWS.to_vec()
    } else {
        args.laws.clone()
    };
    // A row is known by its name in the table, the JSON, the CSV and the
    // findings: two rows of one name once merged without a word (#48 item 13).
    let mut names = std::collections::BTreeSet::new();
    for law in &laws {
        if !names.insert(law.to_string()) {
            bail!("--laws names {law} twice: each row of the table has its own name");
        }
    }
    let mut external = Vec::new();
    for (label, cmd) in &args.controller_cmd {
        if laws.iter().any(|l| l.to_string() == *label) {
            anyhow::bail!(
                "--controller-cmd {label}=…: {label} is a built-in law's name (a row of this \
                 table); name your row otherwise"
            );
        }
        if !names.insert(label.clone()) {
            bail!(
                "--controller-cmd {label}=… is given twice: each row of the table has its own \
                 name; name the second otherwise"
            );
        }
        let command = super::args::command_words(cmd)?;
        run_stack::run::spawn::check_program(&command)
            .with_context(|| format!("--controller-cmd {label}={cmd}"))?;
        external.push(compare::ExternalSpec {
            label: label.clone(),
            command,
        });
    }
    let opts = CompareOptions {
        external,
        runs_dir: args.runs_dir.clone(),
        progress: std::io::stderr().is_terminal(),
        laws,
        seeds: args.seeds,
        threads: super::worker_threads(args.threads),
        series: args.plots.is_some(),
        law_sets: args.law_set.clone(),
        tuning: match args.tuning.as_deref() {
            Some("matched") => Some(controller::Tuning::Matched),
            Some("as-given") => Some(controller::Tuning::AsGiven),
            Some(other) => bail!("--tuning {other}: must be as-given or matched"),
            // Findings compare the laws fairly unless told otherwise (#50).
            None if args.findings => Some(controller::Tuning::Matched),
            None => None,
        },
    };
    if !args.gain_scales.is_empty() {
        return tradeoff(&args, &plan, &opts);
    }
    let result =
        compare::compare(&plan, &opts).with_context(|| format!("comparing on {}", plan.source))?;
    if let Some((path, file)) = csv {
        let mut w = std::io::BufWriter::new(file);
        write_csv(&mut w, &result)
            .and_then(|_| w.flush())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(dir) = &args.plots {
        let n = experiments::compare::plots::write_all(dir, &result, &plan)
            .with_context(|| format!("writing figures to {}", dir.display()))?;
        eprintln!("testbed: wrote {n} figures to {}", dir.display());
    }
    if args.json {
        super::write_stdout(&format!("{}\n", serde_json::to_string_pretty(&result)?))?;
    } else {
        let mut text = table(&result);
        if args.findings {
            text.push_str(&findings(&result));
        }
        super::write_stdout(&text)?;
    }
    let failed: Vec<String> = result
        .laws
        .iter()
        .flat_map(|l| {
            l.runs.iter().filter_map(|r| {
                r.failure
                    .as_ref()
                    .map(|f| format!("{} seed {}: {f}", l.name, r.seed))
            })
        })
        .collect();
    for f in &failed {
        eprintln!("testbed: warning: {f}");
    }
    for w in &result.warnings {
        eprintln!("testbed: warning: {w}");
    }
    // A row with no scored run is no result: say which, last, and fail
    // (#60 item 4: a user's controller that dies on every seed exited 0).
    let none: Vec<&str> = result
        .laws
        .iter()
        .filter(|l| !l.runs.is_empty() && l.failed as usize == l.runs.len())
        .map(|l| l.name.as_str())
        .collect();
    if !none.is_empty() {
        eprintln!(
            "testbed: every run of {} failed: the table has no result for {}",
            none.join(", "),
            if none.len() == 1 { "it" } else { "them" }
        );
        return Ok(ExitCode::FAILURE);
    }
    Ok(ExitCode::SUCCESS)
}

/// `--gain-scales`: the trade-off table (or JSON) and figure.
fn tradeoff(args: &CompareArgs, plan: &scenario::Plan, opts: &CompareOptions) -> Result<ExitCode> {
    if args.csv.is_some() {
        bail!("--csv with --gain-scales: the trade-off has no per-run CSV; use --json");
    }
    let t = experiments::compare::tradeoff::tradeoff(plan, opts, &args.gain_scales)
        .with_context(|| format!("trade-off on {}", plan.source))?;
    if let Some(dir) = &args.plots {
        let n = experiments::compare::plots::write_tradeoff(dir, &t, &plan.scenario.name)
            .with_context(|| format!("writing figures to {}", dir.display()))?;
        eprintln!("testbed: wrote {n} figures to {}", dir.display());
    }
    if args.json {
        super::write_stdout(&format!("{}\n", serde_json::to_string_pretty(&t)?))?;
        return Ok(ExitCode::SUCCESS);
    }
    let mut out = String::new();
    let _ = writeln!(
        out,
        "trade-off on {} ({}): K1 and K2 times each scale; medians over {} seed(s); eff-G: effort beyond the gravity hold; \
         sat: median time saturated (a point with sat > 0 is limited by the motors); * = on the law's Pareto front \
         (IAE against eff-G, against energy)\n",
        plan.scenario.name, plan.source, opts.seeds
    );
    let _ = writeln!(
        out,
        "{:<16} {:>7} {:>12} {:>14} {:>12} {:>7} {:>6} {:>6}",
        "law", "scale", "IAE>Tc", "eff-G>Tc", "energy>Tc", "sat[s]", "failed", "front"
    );
    for p in &t.points {
        let _ = writeln!(
            out,
            "{:<16} {:>7} {:>12} {:>14} {:>12} {:>7} {:>6} {:>6}",
            p.law.to_string(),
            p.scale,
            cell(p.iae.or(Some(f64::INFINITY)), 4),
            cell(p.effort.or(Some(f64::INFINITY)), 1),
            cell(p.energy.or(Some(f64::INFINITY)), 2),
            cell(Some(p.saturated_s), 3),
            p.failed,
            format!(
                "{}{}",
                if p.on_front { "*" } else { "-" },
                if p.on_energy_front { "*" } else { "-" }
            )
        );
    }
    super::write_stdout(&out)?;
    Ok(ExitCode::SUCCESS)
}

/// Columns of the table: (metric, heading, decimals).
const COLUMNS: [(&str, &str, usize); 15] = [
    ("iae", "IAE", 4),
    ("ise", "ISE", 6),
    ("itae", "ITAE", 3),
    ("max_abs_error", "max|e|", 5),
    ("entered_s", "enter[s]", 3),
    ("violation_s", "viol[s]", 3),
    ("violation_after_tc_s", "viol>Tc", 3),
    ("effort_after_tc", "eff>Tc", 1),
    ("effort_beyond_gravity", "eff-G>Tc", 1),
    ("torque_rate", "int dtau^2", 0),
    ("torque_smoothness", "Sm tau", 5),
    ("saturated_s", "sat[s]", 3),
    ("breaches", "breach", 0),
    ("peak_actor_torque", "actor|tau|", 4),
    ("compute_p50_us", "cpu p50us", 2),
];

fn cell(v: Option<f64>, prec: usize) -> String {
    match v {
        // Too small for the column's decimals, but not zero: show it.
        Some(x) if x != 0.0 && x.abs() < 0.5 * 10f64.powi(-(prec as i32)) => format!("{x:.2e}"),
        // Wider than the column: a diverging run, say.
        Some(x) if x.is_finite() && x.abs() >= 1e7 => format!("{x:.2e}"),
        Some(x) if x.is_finite() => format!("{x:.prec$}"),
        Some(_) => "never".into(),
        None => "n/a".into(),
    }
}

/// One row per law (median over seeds; a second "worst" row when N > 1).
pub(crate) fn table(c: &Comparison) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "compare on {} ({}), robot {}: {} s per run, {} seed(s), {} threads, {:.2} s wall",
        c.scenario, c.scenario_source, c.robot, c.duration_s, c.seeds, c.threads, c.wall_time_s
    );
    let _ = writeln!(
        out,
        "metrics after T_c unless marked (Sm tau: the torque's spectral smoothness over the whole run); \
         sums over joints; model: URDF = the law uses the URDF's M, C, G\n"
    );
    let _ = write!(
        out,
        "{:<16} {:<5} {:>6} {:>5} {:>6}",
        "law", "model", "kept", "left", "failed"
    );
    for (_, h, _) in COLUMNS {
        let _ = write!(out, " {h:>10}");
    }
    let _ = writeln!(out);
    for row in &c.laws {
        let stats: Vec<(&str, &compare::Stats)> = if c.seeds > 1 {
            vec![("median", &row.median), ("worst", &row.worst)]
        } else {
            vec![("", &row.median)]
        };
        for (which, s) in stats {
            let name = if which.is_empty() || which == "median" {
                row.name.clone()
            } else {
                format!("  ({which})")
            };
            let model = match (&row.external, row.law.model_based) {
                (Some(_), _) => "ext",
                (None, true) => "URDF",
                (None, false) => "free",
            };
            let (kept, left, failed) = if which == "worst" {
                (String::new(), String::new(), String::new())
            } else {
                (
                    format!("{}/{}", row.kept_envelope, row.runs.len()),
                    row.left_envelope.to_string(),
                    row.failed.to_string(),
                )
            };
            let _ = write!(out, "{name:<16} {model:<5} {kept:>6} {left:>5} {failed:>6}");
            for (key, _, prec) in COLUMNS {
                let _ = write!(out, " {:>10}", cell(s.get(key), prec));
            }
            let _ = writeln!(out);
        }
    }
    let _ = writeln!(
        out,
        "\nkept / left: runs with |e| < k_c at every t >= T_c / not (runs that end before T_c are \
         not judged); failed: runs that stopped, went non-finite or faulted (one rule for every law); \
         enter: when every joint was inside for good; eff-G: effort beyond the URDF's gravity hold, \
         int (tau - G(q))^2; breach: steps the barrier's guard or the funnel's clamp acted (a fact, \
         not a failure)"
    );
    for row in &c.laws {
        if let Some(e) = &row.external {
            let declared = e.declared.as_ref().map_or_else(
                || "declares no law".to_string(),
                |d| format!("law {} ({})", d.name, d.parameters),
            );
            let _ = writeln!(
                out,
                "{}: `{}` in lockstep, {declared}, given the gains of {}",
                row.name, e.command, row.law.law
            );
        }
    }
    if c.seeds > 1 {
        out.push_str(&spread(c));
        out.push_str(&paired(c));
    }
    for w in &c.warnings {
        let _ = writeln!(out, "note: {w}");
    }
    let failed: Vec<String> = c
        .laws
        .iter()
        .flat_map(|l| {
            l.runs.iter().filter_map(move |r| {
                r.failed
                    .as_ref()
                    .map(|why| format!("  {} seed {}: {why}", l.name, r.seed))
            })
        })
        .collect();
    if !failed.is_empty() {
        let _ = writeln!(
            out,
            "FAILED (their metrics count as the worst, never the best):\n{}",
            failed.join("\n")
        );
    }
    out
}

/// The findings, one claim per line with its evidence.
fn findings(c: &Comparison) -> String {
    let tuning = match c.tuning {
        controller::Tuning::Matched => {
            "matched tuning (every law's error dynamics near e = 0 are pd's; --tuning as-given for the textbook gains)"
        }
        controller::Tuning::AsGiven => {
            "as-given tuning (the textbook gains: not a fair fight; --tuning matched for one)"
        }
    };
    let mut out = format!(
        "\nfindings on {} under {tuning}\n(rules: docs/compare-and-sweeps.md#findings-the-papers-claims-checked):\n",
        c.scenario
    );
    for f in &c.findings {
        let _ = writeln!(out, "  [{}] {}\n      {}", f.verdict, f.claim, f.evidence);
    }
    out
}

/// The metrics of the spread table: (metric, heading, decimals).
const SPREAD: [(&str, &str, usize); 3] = [
    ("iae", "IAE", 4),
    ("max_abs_error", "max|e|", 5),
    ("effort_after_tc", "eff>Tc", 1),
];

/// Median, 95 % interval of the median and IQR of a few metrics per law.
fn spread(c: &Comparison) -> String {
    let mut out = String::new();
    let ci = c.laws.first().and_then(|l| l.ci95);
    let _ = writeln!(
        out,
        "\nover {} seeds: median [95 % interval of the median] (interquartile range q3 - q1){}",
        c.seeds,
        ci.map_or(String::new(), |ci| format!(
            "; the interval is order statistics x({}) .. x({}), coverage {:.1} %",
            ci.k,
            ci.high_rank,
            100.0 * ci.coverage
        ))
    );
    let _ = write!(out, "{:<16}", "law");
    for (_, h, _) in SPREAD {
        let _ = write!(out, " {h:>34}");
    }
    let _ = writeln!(out);
    for row in &c.laws {
        let _ = write!(out, "{:<16}", row.name.clone());
        for (key, _, prec) in SPREAD {
            let get = |s: &compare::Stats| s.get(key);
            let iqr = match (get(&row.q1), get(&row.q3)) {
                (Some(a), Some(b)) if a.is_finite() && b.is_finite() => Some(b - a),
                _ => Some(f64::INFINITY),
            };
            let text = format!(
                "{} [{}, {}] ({})",
                cell(get(&row.median), prec),
                cell(get(&row.ci95_low), prec),
                cell(get(&row.ci95_high), prec),
                cell(iqr, prec)
            );
            let _ = write!(out, " {text:>34}");
        }
        let _ = writeln!(out);
    }
    out
}

/// The paired tests, one line per law and metric.
fn paired(c: &Comparison) -> String {
    let mut out = String::new();
    let Some(first) = c.paired.first() else {
        return out;
    };
    let _ = writeln!(
        out,
        "\npaired on the same seeds, baseline {} against each law: Wilcoxon signed-rank, two-sided \
         (better/worse/ties: seeds where {} did better, worse, the same; diff: median of {} - law; \
         p Holm: corrected over all {} tests)",
        first.law,
        first.law,
        first.law,
        c.paired.len()
    );
    let _ = writeln!(
        out,
        "{:<16} {:<22} {:>6} {:>6} {:>5} {:>12} {:>10} {:>10}",
        "law", "metric", "better", "worse", "ties", "diff", "p", "p Holm"
    );
    for p in &c.paired {
        let t = &p.test;
        let _ = writeln!(
            out,
            "{:<16} {:<22} {:>6} {:>6} {:>5} {:>12} {:>10.2e} {:>10.2e}",
            p.versus.to_string(),
            p.metric,
            t.a_smaller,
            t.b_smaller,
            t.ties,
            signed(t.median_difference),
            t.p_value,
            p.p_holm
        );
    }
    out
}

fn signed(x: f64) -> String {
    match x {
        x if x == f64::INFINITY => "+worst".into(),
        x if x == f64::NEG_INFINITY => "-worst".into(),
        x => format!("{x:.3e}"),
    }
}

/// One row per law and seed: `law,model_based,seed,failed,failure,
/// kept_envelope,envelope,` then every metric (`failure`: why it failed,
/// quoted; `envelope`: kept, left or not-judged).
fn write_csv(w: &mut impl std::io::Write, c: &Comparison) -> std::io::Result<()> {
    let names: Vec<&str> = METRICS.iter().map(|m| m.name).collect();
    writeln!(
        w,
        "law,model_based,seed,failed,failure,kept_envelope,envelope,{}",
        names.join(",")
    )?;
    for row in &c.laws {
        for run in &row.runs {
            let one = compare::stats_of(run);
            let values: Vec<String> = one
                .0
                .iter()
                .map(|(_, v)| {
                    if v.is_finite() {
                        format!("{v:?}")
                    } else {
                        String::new()
                    }
                })
                .collect();
            let failure = run
                .failed
                .as_deref()
                .map_or_else(String::new, |f| format!("\"{}\"", f.replace('"', "\"\"")));
            writeln!(
                w,
                "{},{},{},{},{failure},{},{},{}",
                row.name,
                row.law.model_based,
                run.seed,
                run.failed.is_some(),
                run.envelope == compare::Envelope::Kept,
                run.envelope.as_str(),
                values.join(",")
            )?;
        }
    }
    Ok(())
}
