//! A user's controller as a row of `testbed compare` (`--controller-cmd
//! NAME=CMD`): each seed run through the lockstep stack with the command
//! as the controller node, scored like the built-in laws, its declared law
//! named in the row.

use analysis::law_info::LawInfo;
use analysis::summary::SummaryBuilder;
use analysis::timing::Percentiles;
use scenario::Plan;

use crate::compare::runs::plan_for;
use crate::compare::scores::{row, scored};
use crate::compare::types::{CompareError, CompareOptions, ExternalRow, ExternalSpec, LawRow};

/// A user's controller over every seed: each seed's plan (the scenario's
/// law and gains, that seed's draws) run in lockstep with the command as
/// the controller node, one run at a time.
pub(crate) fn external_row(
    plan: &Plan,
    spec: &ExternalSpec,
    opts: &CompareOptions,
    bar: Option<&indicatif::ProgressBar>,
) -> Result<LawRow, CompareError> {
    let law = plan.undrawn.controller.law;
    let mut runs = Vec::new();
    let mut declared = None;
    for s in 0..opts.seeds {
        let p = plan_for(plan, law, s, opts.tuning, &opts.law_sets)?;
        let seed = p.scenario.seed;
        let run = run_stack::run::run(run_stack::run::RunOptions {
            plan: p,
            mode: wire::Mode::Lockstep,
            csv: None,
            external: Vec::new(),
            runs_dir: opts.runs_dir.clone(),
            name: None,
            progress: false,
            realtime_setup: false,
            verbose: false,
            controller_cmd: Some(spec.command.clone()),
            live: None,
            log_compression: logger::LogCompression::default(),
        });
        if let Some(b) = bar {
            b.inc(1);
        }
        runs.push(match run {
            Ok(o) => {
                let meta = |k: &str| o.analysis.contents.run.get(k).cloned().unwrap_or_default();
                let name = meta("controller_name");
                declared = (!name.is_empty()).then(|| analysis::report::ExternalLaw {
                    name,
                    parameters: meta("controller_params"),
                    // Per run, not per law: in each run's own summary.
                    diagnostics: Vec::new(),
                });
                scored(
                    seed,
                    None,
                    o.analysis.summary,
                    o.analysis.timing.controller_compute_us,
                    None,
                )
            }
            Err(e) => {
                // One line: a policy's traceback with its paths stays in
                // the run's nodes/controller.log (#48 item 16).
                let why = format!("the run failed: {}", e.brief());
                let names = plan.robot.model.joint_names();
                let empty = SummaryBuilder::new(names, plan.dt(), plan.scenario.controller.tc);
                let mut run = scored(
                    seed,
                    Some(why),
                    empty.finish(),
                    Percentiles::of(Vec::new()),
                    None,
                );
                // A run meant to reach T_c that crashed did not keep the
                // envelope: "not judged" is for runs that end before T_c
                // by design (#50).
                if plan.steps as f64 * plan.dt() > plan.scenario.controller.tc {
                    run.envelope = crate::compare::types::Envelope::Left;
                }
                run
            }
        });
    }
    let mut r = row(LawInfo::of(&plan.undrawn.controller), runs);
    r.name = spec.label.clone();
    r.external = Some(ExternalRow {
        command: shell_words::join(&spec.command),
        declared,
    });
    Ok(r)
}
