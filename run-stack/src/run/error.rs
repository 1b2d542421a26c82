//! Why a run failed, and how the log records each failure.

use bus::BusError;
use wire::{MAX_DOF, NodeKind, RunEnd};

use analysis::analyse::AnalysisError;

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The bus failed.
    #[error(transparent)]
    Wire(#[from] BusError),
    /// A file could not be written.
    #[error("{0}: {1}")]
    Output(String, std::io::Error),
    /// The live view's address cannot be listened on (in use, say).
    #[error(
        "--live {0}: cannot listen there: {1} (is another run or Foxglove bridge using it? \
         give another port: --live 127.0.0.1:PORT)"
    )]
    LivePort(std::net::SocketAddr, std::io::Error),
    /// A node could not be started.
    #[error("cannot start the {node} node{}: {cause}", if .command.is_empty() { String::new() } else { format!(" (`{}`)", .command) })]
    Spawn {
        /// Which node.
        node: &'static str,
        /// The user's command that was to run as the node (empty: `testbed node`).
        command: String,
        /// The cause.
        cause: std::io::Error,
    },
    /// The scenario asks for something this run cannot give.
    #[error("{reason}")]
    Scenario {
        /// What, and what to do.
        reason: String,
    },
    /// An external controller's declaration, or the scenario's values for it.
    #[error("the controller command `{command}`: {reason}")]
    External {
        /// The command.
        command: String,
        /// What is wrong.
        reason: String,
    },
    /// A node died or exited before the run was over.
    #[error("the {node} node {how}{}", if .stderr.is_empty() { String::new() } else { format!("; its last words:\n{}", .stderr) })]
    NodeFailed {
        /// Which node.
        node: &'static str,
        /// How it ended.
        how: String,
        /// The last lines it wrote to stderr.
        stderr: String,
    },
    /// Nodes did not connect in time.
    #[error("nodes did not report ready within {secs} s: {}", .missing.join(", "))]
    StartTimeout {
        /// The nodes that did not connect.
        missing: Vec<&'static str>,
        /// The limit.
        secs: u64,
    },
    /// No progress for too long.
    #[error("the run stalled at step {step} of {steps} (nothing for {secs} s)")]
    Stalled {
        /// Rows done.
        step: u64,
        /// Rows expected.
        steps: u64,
        /// The limit.
        secs: u64,
    },
    /// Nodes that did not finish after the plant's last step.
    #[error(
        "the {} node did not finish within {secs} s of the plant's last step: it is stopped, \
         spinning or deadlocked", .nodes.join(" and the ")
    )]
    NotFinished {
        /// The nodes.
        nodes: Vec<&'static str>,
        /// The limit.
        secs: u64,
    },
    /// A node stopped saying it is alive while the run went on.
    #[error(
        "the {node} node has not been heard from for {secs} s: it is stopped, spinning or \
         deadlocked (step {step} of {steps})"
    )]
    Silent {
        /// The node heard from least recently.
        node: &'static str,
        /// The limit.
        secs: u64,
        /// The plant's last reported step.
        step: u64,
        /// Steps of the run.
        steps: u64,
    },
    /// A topic was not delivered to the logger: in lockstep, which loses
    /// nothing by design, any row missing; in real time, a topic never
    /// received.
    #[error(
        "the run's log lacks {missing} of {steps} steps, so its figures are not printed (the \
         logger received: {received}); a topic was not delivered, which is a fault of the \
         shared-memory transport: run it again. The log is kept: {log}"
    )]
    LogIncomplete {
        /// Rows missing.
        missing: u64,
        /// Rows expected.
        steps: u64,
        /// The logger's per-topic counts.
        received: String,
        /// The log.
        log: String,
    },
    /// Ctrl-C or SIGTERM.
    #[error("interrupted; all nodes stopped")]
    Interrupted,
    /// The log could not be analysed.
    #[error(transparent)]
    Analysis(#[from] AnalysisError),
    /// The arm has more joints than the wire carries.
    #[error("the robot has {dof} actuated joints; the wire carries at most {MAX_DOF}")]
    TooManyJoints {
        /// Joints of the arm.
        dof: usize,
    },
}

impl RunError {
    /// How the run ended, for STOP and the log: the node it lost if one is to blame.
    pub fn run_end(&self) -> RunEnd {
        let lost = |name: Option<&&str>| {
            NodeKind::ALL
                .into_iter()
                .find(|k| name == Some(&k.name()))
                .map_or(RunEnd::Failed, RunEnd::LostNode)
        };
        match self {
            RunError::Interrupted => RunEnd::Interrupted,
            RunError::NodeFailed { node, .. } => lost(Some(node)),
            RunError::NotFinished { nodes, .. } => lost(nodes.first()),
            RunError::Silent { node, .. } => lost(Some(node)),
            _ => RunEnd::Failed,
        }
    }
}

/// The most characters of a failed run's reason in a table or JSON.
pub const BRIEF_CHARS: usize = 200;

impl RunError {
    /// Why the run failed in one line, for a table's `failed` field: a
    /// node's end with the last line it wrote (a Python traceback's last
    /// line is the exception), never the traceback with its file paths;
    /// the whole text is in the run folder's `nodes/<node>.log`. Other
    /// failures are their message's first line. Cut to `BRIEF_CHARS` characters.
    pub fn brief(&self) -> String {
        let text = match self {
            RunError::NodeFailed { node, how, stderr } => {
                let last = stderr
                    .lines()
                    .map(str::trim)
                    .rfind(|l| !l.is_empty())
                    .map(|l| format!(": {l}"))
                    .unwrap_or_default();
                format!("the {node} node {how}{last} (whole output: nodes/{node}.log of the run)")
            }
            other => other
                .to_string()
                .lines()
                .next()
                .unwrap_or_default()
                .to_string(),
        };
        match text.char_indices().nth(BRIEF_CHARS) {
            None => text,
            Some((at, _)) => format!("{}…", &text[..at]),
        }
    }
}

impl RunError {
    /// A node that reported a failure has usually exited by the time every
    /// node was stopped: its last stderr lines say why.
    pub(crate) fn with_stderr_of(self, children: &mut super::spawn::Children) -> Self {
        match self {
            RunError::NodeFailed { node, how, stderr } if stderr.is_empty() => {
                let kind = NodeKind::ALL.into_iter().find(|k| k.name() == node);
                let stderr = kind
                    .and_then(|k| children.exit_of(k))
                    .map(|(_, tail)| tail)
                    .unwrap_or_default();
                RunError::NodeFailed { node, how, stderr }
            }
            other => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// #48 item 16: a user's policy that raised keeps one line in a
    /// table, the exception, not the traceback and its paths.
    #[test]
    fn a_failed_nodes_brief_is_its_last_line() {
        let e = RunError::NodeFailed {
            node: "controller",
            how: "exited with status 1".into(),
            stderr: "Traceback (most recent call last):\n  File \"/home/me/secret/policy.py\", \
                     line 3, in <module>\n    raise ValueError('bad weights')\n\
                     ValueError: bad weights\n\n"
                .into(),
        };
        let b = e.brief();
        assert_eq!(
            b,
            "the controller node exited with status 1: ValueError: bad weights \
             (whole output: nodes/controller.log of the run)"
        );
        assert!(e.to_string().contains("/home/me/secret"));
        let long = RunError::NodeFailed {
            node: "controller",
            how: "exited".into(),
            stderr: "x".repeat(10_000),
        };
        assert_eq!(long.brief().chars().count(), BRIEF_CHARS + 1);
        let other = RunError::Scenario {
            reason: "first\nsecond".into(),
        };
        assert_eq!(other.brief(), "first");
    }
}
