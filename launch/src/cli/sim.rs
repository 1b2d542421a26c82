//! `testbed sim`: the run in one process.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::process::ExitCode;
use std::time::Instant;

use analysis::{csv_out, summary::SummaryBuilder};
use anyhow::{Context, Result};
use run_stack::sim as in_process;

use super::args::SimArgs;
use super::{load, print_report};
use analysis::report::Report;

pub(crate) fn sim(args: SimArgs) -> Result<ExitCode> {
    let plots = args.plots;
    let args = args.common;
    let plan = load(&args, None)?;
    super::no_external(&plan, "sim")?;
    let inputs = super::outputs::plan_inputs(args.scenario.as_deref(), &plan);
    let mut csv = match &args.csv {
        Some(path) => {
            super::outputs::refuse_input("--csv", path, &inputs)?;
            let file = File::create(path)
                .with_context(|| format!("cannot create CSV file {}", path.display()))?;
            let mut w = BufWriter::new(file);
            writeln!(w, "{}", csv_out::header(plan.robot.model.dof()))
                .with_context(|| format!("writing {}", path.display()))?;
            Some(w)
        }
        None => None,
    };
    let mut summary = SummaryBuilder::new(
        plan.robot.model.joint_names(),
        plan.dt(),
        plan.scenario.controller.tc,
    )
    .with_gravity(&plan.robot.model);
    let mut series = plots
        .as_ref()
        .map(|_| analysis::Series::new(plan.robot.model.dof()));
    let start = Instant::now();
    let mut costs = in_process::StepCosts::default();
    let result = in_process::run_measured(&plan, Some(&mut costs), |r| {
        summary.add(r);
        if let Some(s) = series.as_mut() {
            s.add(r);
        }
        match csv.as_mut() {
            Some(w) => csv_out::write_row(w, r),
            None => Ok(()),
        }
    });
    let wall = start.elapsed().as_secs_f64();
    // Keep what was written even if the loop failed part-way.
    if let (Some(mut w), Some(path)) = (csv, &args.csv) {
        w.flush()
            .with_context(|| format!("writing {}", path.display()))?;
    }
    result.with_context(|| format!("running {}", plan.source))?;
    if let (Some(dir), Some(s)) = (&plots, &series) {
        let written = analysis::plots::write_all(dir, s, &plan)
            .with_context(|| format!("writing figures to {}", dir.display()))?;
        eprintln!("testbed: wrote {written} figures to {}", dir.display());
    }
    let report = Report::from_sim(&plan, summary.finish(), wall, costs.controller_us.finish());
    print_report(&report, args.json)?;
    Ok(ExitCode::SUCCESS)
}
