//! `testbed tune`: a law's search space from the parameter table, and the
//! tuner itself, which is Optuna in Python (`python -m testbed.tune`) over
//! the in-process core: this forwards to it.

use std::process::ExitCode;

use anyhow::{Context, Result, bail};

use super::args::TuneArgs;

/// The tuner's Python when neither --python nor TESTBED_PYTHON names one:
/// the environment `bash python/build-module.sh` makes.
const DEFAULT_PYTHON: &str = "target/python-venv/bin/python3";

/// Prints a search space, or runs the Python tuner with the arguments.
pub(crate) fn tune(args: TuneArgs) -> Result<ExitCode> {
    if let Some(law) = args.print_space {
        super::write_stdout(&space_text(law))?;
        return Ok(ExitCode::SUCCESS);
    }
    let forwarded: Vec<String> = match &args.report {
        Some(file) => vec!["report".into(), file.display().to_string()],
        None if args.args.is_empty() => bail!(
            "testbed tune needs a command: run, report, best or evaluate \
             (`testbed tune run --help`), or --print-space LAW"
        ),
        None => args.args.clone(),
    };
    let python = args
        .python
        .clone()
        .or_else(|| std::env::var("TESTBED_PYTHON").ok())
        .unwrap_or_else(|| DEFAULT_PYTHON.to_string());
    let status = std::process::Command::new(&python)
        .args(["-m", "testbed.tune"])
        .args(&forwarded)
        .status()
        .with_context(|| {
            format!(
                "starting {} (the tuner is Optuna in Python: make that environment with \
                 `bash python/build-module.sh` and `pip install optuna`, or name another \
                 with --python)",
                python
            )
        })?;
    Ok(exit_of(status))
}

/// The tuner's exit status as this command's (a signal as 128 + its number).
fn exit_of(status: std::process::ExitStatus) -> ExitCode {
    use std::os::unix::process::ExitStatusExt;
    match (status.code(), status.signal()) {
        (Some(c), _) => ExitCode::from(u8::try_from(c).unwrap_or(1)),
        (None, Some(s)) => ExitCode::from(u8::try_from(128 + s).unwrap_or(1)),
        (None, None) => ExitCode::FAILURE,
    }
}

/// The search space as lines: key, what it tunes, range.
fn space_text(law: controller::LawName) -> String {
    let mut out = format!(
        "{law}: the keys `testbed tune` searches (from controller/src/params.rs)\n\
         {:<16} {:<7} range\n",
        "key", "role"
    );
    for d in controller::search_space(law) {
        let role = serde_json::to_value(d.role).ok();
        let role = role.as_ref().and_then(|r| r.as_str()).unwrap_or("?");
        out += &format!("{:<16} {:<7} {}\n", d.key, role, d.range.describe());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_space_lists_the_laws_keys_with_their_ranges() {
        let t = space_text(controller::LawName::Pd);
        assert!(t.contains("k1 ") && t.contains("k2 "), "{t}");
        assert!(!t.contains("sigma_a"), "{t}");
        let t = space_text(controller::LawName::Nac);
        assert!(
            t.contains("sigma_a") && t.contains("[0.01, 10000] log"),
            "{t}"
        );
        assert!(
            t.contains("rbf_layout") && t.contains("one of diagonal, per-input"),
            "{t}"
        );
    }
}
