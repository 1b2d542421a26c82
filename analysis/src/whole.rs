//! Whether a log holds the whole run: every topic each run logs, and as
//! many messages of each as the logger received. A log rewritten without
//! `/timing` or `/command` still has complete rows (a row is a state and
//! its diagnostics), so it once replayed `clean`.

use std::collections::HashMap;

use logger::{LogContents, LogMessage};

/// The topics every run logs: the plant's state and timing, the
/// reference, the controller's command and diagnostics.
pub const ALWAYS_LOGGED: [&str; 5] = [
    wire::JointState::LOG_TOPIC,
    wire::ReferenceSample::LOG_TOPIC,
    wire::Command::LOG_TOPIC,
    wire::ControllerDiagnostics::LOG_TOPIC,
    wire::Timing::LOG_TOPIC,
];

/// Longest stored value quoted in a reason.
const QUOTE_CHARS: usize = 80;

/// Why the log at hand is not the whole run, one clause each (empty: it
/// is). `counts` are the messages read per topic; `own` is true when the
/// run's controller declared its own diagnostics (then logged every step).
pub fn gaps(contents: &LogContents, counts: &HashMap<String, u64>, own: bool) -> Vec<String> {
    let held = |topic: &str| counts.get(topic).copied().unwrap_or(0);
    let missing: Vec<&str> = ALWAYS_LOGGED
        .into_iter()
        .chain(own.then_some(wire::OwnDiagnostics::LOG_TOPIC))
        .filter(|t| held(t) == 0)
        .collect();
    let mut out = Vec::new();
    if !missing.is_empty() {
        out.push(format!("it has no {} messages", missing.join(", ")));
    }
    // The logger's own counts (absent from a log it never finished).
    for (key, value) in contents.stats.iter().flatten() {
        let Some(name) = key.strip_suffix(".received") else {
            continue;
        };
        let topic = format!("/{name}");
        match value.parse::<u64>() {
            Ok(received) if received != held(&topic) && !missing.contains(&topic.as_str()) => out
                .push(format!(
                    "it holds {} {topic} messages where the logger received {received}",
                    held(&topic)
                )),
            Ok(_) => {}
            Err(_) => out.push(format!(
                "testbed.log_stats {key} is not a count ({:?})",
                value.chars().take(QUOTE_CHARS).collect::<String>()
            )),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use std::collections::BTreeMap;

    use super::*;

    fn counts(of: &[(&str, u64)]) -> HashMap<String, u64> {
        of.iter().map(|(t, n)| (t.to_string(), *n)).collect()
    }

    fn whole() -> HashMap<String, u64> {
        counts(&ALWAYS_LOGGED.map(|t| (t, 10)))
    }

    #[test]
    fn a_whole_log_has_no_gaps() {
        let contents = LogContents {
            stats: Some(BTreeMap::from([("timing.received".into(), "10".into())])),
            ..LogContents::default()
        };
        assert_eq!(gaps(&contents, &whole(), false), Vec::<String>::new());
    }

    /// Issue 48 item 1: a log rewritten without /timing and /command.
    #[test]
    fn a_log_without_timing_or_command_names_them() {
        let mut c = whole();
        c.remove("/timing");
        c.remove("/command");
        let g = gaps(&LogContents::default(), &c, false);
        assert_eq!(g, ["it has no /command, /timing messages"]);
        // Declared own diagnostics are logged every step too.
        let g = gaps(&LogContents::default(), &whole(), true);
        assert_eq!(g, ["it has no /controller/own_diagnostics messages"]);
    }

    #[test]
    fn fewer_messages_than_the_logger_received_are_a_gap() {
        let contents = LogContents {
            stats: Some(BTreeMap::from([
                ("timing.received".into(), "12".into()),
                ("timing.dropped".into(), "0".into()),
                ("command.received".into(), "x".repeat(500)),
            ])),
            ..LogContents::default()
        };
        let g = gaps(&contents, &whole(), false);
        assert_eq!(g.len(), 2, "{g:?}");
        assert!(
            g.iter()
                .any(|r| r.contains("command.received is not a count") && r.len() < 150)
        );
        assert!(g.contains(&"it holds 10 /timing messages where the logger received 12".into()));
    }
}
