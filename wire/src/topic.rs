//! The topics of a run and their quality of service: the one place where
//! service names, buffer sizes and delivery are decided. Rust nodes open
//! them through the `bus` crate; other languages' nodes get them from the
//! generated bindings.

use std::time::Duration;

/// A pub/sub topic and its paired event service (same name).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Topic {
    /// Plant → controller, logger: [`crate::JointState`].
    JointState,
    /// Trajectory → controller, logger: [`crate::ReferenceSample`].
    Reference,
    /// Controller → plant, logger: [`crate::Command`].
    Command,
    /// Controller → logger: [`crate::ControllerDiagnostics`].
    Diagnostics,
    /// External controller → logger: [`crate::OwnDiagnostics`].
    OwnDiagnostics,
    /// Plant → logger: [`crate::Timing`].
    Timing,
    /// Plant → logger: [`crate::ContactState`] (contact scenarios only).
    Contact,
    /// Launcher → nodes: [`crate::Control`].
    Control,
    /// Nodes → launcher: [`crate::NodeStatus`].
    Status,
}

impl Topic {
    /// Every topic.
    pub const ALL: &[Topic] = &[
        Topic::JointState,
        Topic::Reference,
        Topic::Command,
        Topic::Diagnostics,
        Topic::OwnDiagnostics,
        Topic::Timing,
        Topic::Contact,
        Topic::Control,
        Topic::Status,
    ];

    /// Service name (under the run prefix).
    pub fn name(self) -> &'static str {
        match self {
            Topic::JointState => "testbed/joint_state",
            Topic::Reference => "testbed/reference",
            Topic::Command => "testbed/command",
            Topic::Diagnostics => "testbed/diagnostics",
            Topic::OwnDiagnostics => "testbed/own_diagnostics",
            Topic::Timing => "testbed/timing",
            Topic::Contact => "testbed/contact",
            Topic::Control => "testbed/control",
            Topic::Status => "testbed/status",
        }
    }

    /// Whether some reader blocks on this topic's wake-ups. The others are
    /// read by polling (the logger every 10 ms, the controller when a state
    /// arrives), so their publishers skip the notify syscalls.
    pub fn has_waiters(self) -> bool {
        matches!(
            self,
            Topic::JointState | Topic::Command | Topic::Control | Topic::Status
        )
    }

    /// Status has one publisher per node; every other topic has one owner.
    pub fn max_publishers(self) -> usize {
        match self {
            Topic::Status => 8,
            _ => 1,
        }
    }

    /// Notifiers the paired event service allows.
    pub fn max_notifiers(self) -> usize {
        self.max_publishers().max(2)
    }
}

/// Samples a subscriber can hold before the publisher waits or drops:
/// about 50 ms of a lockstep run, so batch readers (logger, launcher) that
/// wake every 10 ms never hold the loop back.
pub const SUBSCRIBER_BUFFER: usize = 2048;
/// Subscribers per topic: the process that uses it, the logger, the
/// launcher, and one spare for a debugging tool.
pub const MAX_SUBSCRIBERS: usize = 4;
/// Nodes that may open one service: four processes, the launcher, spares.
pub const MAX_NODES: usize = 10;
/// How long a lossless publisher waits for a full subscriber before giving up.
pub const LOSSLESS_TIMEOUT: Duration = Duration::from_secs(10);

/// What a publisher does when a subscriber's buffer is full.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delivery {
    /// Wait until there is room (lockstep: no sample is ever lost), failing
    /// after 10 s so a stuck reader cannot hang the run.
    Lossless,
    /// Skip that subscriber for this sample (real time: never wait); the
    /// receiver sees the gap in sequence numbers.
    DropWhenFull,
}

/// Every run's shared-memory prefix starts so (stale runs are found by it).
pub const RUN_PREFIX_STEM: &str = "tbrun";
