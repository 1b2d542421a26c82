//! `testbed`: run the paper's controller on a simulated arm.

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    match cli::run() {
        Ok(code) => code,
        Err(e) if e.is::<cli::StdoutClosed>() => ExitCode::from(cli::EXIT_STDOUT_CLOSED),
        Err(e) => {
            eprintln!("testbed: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
