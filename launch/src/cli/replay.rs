//! `testbed replay`: everything from a run's log.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::process::ExitCode;

use anyhow::{Context, Result};

use super::args::ReplayArgs;
use super::print_report;
use analysis::report::Report;

pub(crate) fn replay(args: ReplayArgs) -> Result<ExitCode> {
    if let Some(path) = &args.csv {
        super::outputs::refuse_input("--csv", path, std::slice::from_ref(&args.log))?;
    }
    let mut csv = match &args.csv {
        Some(path) => {
            Some(BufWriter::new(File::create(path).with_context(|| {
                format!("cannot create CSV file {}", path.display())
            })?))
        }
        None => None,
    };
    let csv_name = args
        .csv
        .as_ref()
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    let analysis = analysis::analyse::analyse(
        &args.log,
        analysis::analyse::AnalyseOptions {
            csv: csv
                .as_mut()
                .map(|w| (csv_name.as_str(), w as &mut dyn Write)),
            verify: args.verify,
            series: args.plots.is_some(),
        },
    )?;
    // Re-driving nothing proves nothing: a difference of 0 over 0 steps
    // is not a verification.
    if matches!(analysis.verify, Some((_, 0))) {
        let why = match analysis.timing.reasons.as_slice() {
            [] => String::new(),
            reasons => format!("; the log is invalid: {}", reasons.join("; ")),
        };
        anyhow::bail!(
            "{}: --verify found no step to re-drive (the log holds no complete step){why}",
            args.log.display()
        );
    }
    if let (Some(dir), Some(series)) = (&args.plots, &analysis.series) {
        let written = analysis::plots::write_all(dir, series, &analysis.plan)
            .with_context(|| format!("writing figures to {}", dir.display()))?;
        eprintln!("testbed: wrote {} figures to {}", written, dir.display());
    }
    let verdict = analysis.timing.verdict;
    print_report(&Report::from_log(analysis), args.json)?;
    // As `run` exits: a script must not take an invalid log's figures.
    Ok(super::verdict_status(verdict, "log"))
}
