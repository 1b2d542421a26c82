//! When the shared-memory transport, not the run, failed: iceoryx2 0.10
//! now and then leaves a pair of ports unconnected when a run starts,
//! mostly without a word (the logger and one of the controller's topics,
//! about once in 300 lockstep runs under load). A node then fails saying
//! [`bus::CONNECTION_FAILED`], or a lockstep log lacks steps; the run is
//! started again, from scratch, in a new domain. Lockstep runs are
//! deterministic, so a run started again gives the same bits.

use crate::mode::Mode;
use analysis::analyse::LogAnalysis;

use super::{RunError, RunOptions, RunOutcome};

/// Runs in all, the first included.
const ATTEMPTS: u32 = 3;

/// Runs `once`, again while the transport is to blame (not with nodes
/// started by hand: they would have to be started again too).
pub(super) fn with_retries(
    opts: &RunOptions,
    once: impl Fn(&RunOptions) -> Result<RunOutcome, RunError>,
) -> Result<RunOutcome, RunError> {
    let mut attempt = 1;
    loop {
        match once(opts) {
            Err(e)
                if is_transport_failure(&e) && attempt < ATTEMPTS && opts.external.is_empty() =>
            {
                eprintln!(
                    "testbed: {e}\ntestbed: the shared-memory transport failed to connect; \
                     starting the run again ({} of {ATTEMPTS})",
                    attempt + 1
                );
                attempt += 1;
            }
            other => return other,
        }
    }
}

/// A failure of the transport rather than of the run.
fn is_transport_failure(e: &RunError) -> bool {
    match e {
        RunError::LogIncomplete { .. } => true,
        RunError::NodeFailed { stderr, .. } => stderr.contains(bus::CONNECTION_FAILED),
        _ => false,
    }
}

/// The transport's failure a finished log shows, if any: in lockstep any
/// step missing; in real time, where samples may be dropped, a topic the
/// logger never received at all. `contact`: the plant simulates contact
/// (and so publishes its contact samples).
pub(super) fn check_log(analysis: &LogAnalysis, mode: Mode, contact: bool) -> Result<(), RunError> {
    let key = |c: Option<&str>| c.map(|c| format!("{}.received", c.trim_start_matches('/')));
    // Own diagnostics come only from a controller that declared some,
    // contact samples only from a plant with contact.
    let own = key(<wire::OwnDiagnostics as wire::Bound>::CHANNEL);
    let touch = key(<wire::ContactState as wire::Bound>::CHANNEL);
    let expected = |k: &str| {
        (!analysis.own_diagnostics.is_empty() || own.as_deref() != Some(k))
            && (contact || touch.as_deref() != Some(k))
    };
    let topic_never_came = analysis.expected_rows > 0
        && analysis
            .contents
            .stats
            .iter()
            .flatten()
            .any(|(k, v)| k.ends_with(".received") && v == "0" && expected(k));
    let lost = match mode {
        Mode::Lockstep => analysis.missing_rows > 0,
        Mode::Realtime => topic_never_came,
    };
    if lost {
        Err(incomplete(analysis))
    } else {
        Ok(())
    }
}

/// The error for a log with rows missing, with the logger's counts.
fn incomplete(analysis: &LogAnalysis) -> RunError {
    let received = analysis
        .contents
        .stats
        .iter()
        .flatten()
        .filter_map(|(k, v)| Some(format!("{} {v}", k.strip_suffix(".received")?)))
        .collect::<Vec<_>>()
        .join(", ");
    RunError::LogIncomplete {
        missing: analysis.missing_rows,
        steps: analysis.expected_rows,
        received,
        log: analysis.contents.path.display().to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_connection_failures_are_the_transports() {
        let failed = |stderr: &str| RunError::NodeFailed {
            node: "plant",
            how: "exited with status 1".into(),
            stderr: stderr.into(),
        };
        assert!(is_transport_failure(&failed(&format!(
            "testbed: {} publisher 5 and subscriber 6 of testbed/joint_state",
            bus::CONNECTION_FAILED
        ))));
        assert!(!is_transport_failure(&failed("plant: NaN in the state")));
        assert!(!is_transport_failure(&RunError::Interrupted));
        assert!(is_transport_failure(&RunError::LogIncomplete {
            missing: 400,
            steps: 400,
            received: String::new(),
            log: String::new(),
        }));
    }
}
