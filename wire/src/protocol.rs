//! The node protocol's contract: the timing modes, how often a running
//! node reports, when the launcher names a silent one, and sim time in
//! seconds. The protocol's runtime (`NodeLink`) is in the `bus` crate.

use std::time::Duration;

use crate::Delivery;

/// Timing mode of a multi-process run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// The plant steps on an absolute-deadline grid at the scenario rate,
    /// holding the latest command; a late command is a deadline miss.
    Realtime,
    /// The plant is the clock: it publishes state k and steps only when
    /// command k has arrived. Deterministic, as fast as the machine allows.
    Lockstep,
}

impl Mode {
    /// The code START carries ([`crate::Control::code`]).
    pub fn code(self) -> u32 {
        match self {
            Mode::Realtime => 1,
            Mode::Lockstep => 2,
        }
    }

    /// The command-line spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Realtime => "realtime",
            Mode::Lockstep => "lockstep",
        }
    }

    /// What a publisher of this mode does with a full reader: wait
    /// (lockstep: nothing is lost) or skip it (real time: never wait).
    pub fn delivery(self) -> Delivery {
        match self {
            Mode::Lockstep => Delivery::Lossless,
            Mode::Realtime => Delivery::DropWhenFull,
        }
    }
}

/// A spelling that is not a [`Mode`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{0}' is not a mode: realtime or lockstep")]
pub struct UnknownMode(pub String);

impl std::str::FromStr for Mode {
    type Err = UnknownMode;

    fn from_str(s: &str) -> Result<Self, UnknownMode> {
        match s {
            "realtime" => Ok(Mode::Realtime),
            "lockstep" => Ok(Mode::Lockstep),
            other => Err(UnknownMode(other.into())),
        }
    }
}

/// How often a node says it is alive (its last status again) while it
/// checks in: the launcher names a node silent for [`SILENT_AFTER`].
pub const HEARTBEAT: Duration = Duration::from_millis(100);

/// A node whose status has not been heard for this long is stopped,
/// spinning or deadlocked: the launcher ends the run and names it.
pub const SILENT_AFTER: Duration = Duration::from_secs(3);

/// Seconds from integer nanoseconds: the one conversion every process
/// uses, so in-process and multi-process runs compute the same bits.
pub fn ns_to_s(ns: u64) -> f64 {
    ns as f64 / 1e9
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[test]
    fn modes_parse_from_their_spelling_only() {
        for m in [Mode::Realtime, Mode::Lockstep] {
            assert_eq!(m.as_str().parse::<Mode>().unwrap(), m);
        }
        assert!(
            "real-time"
                .parse::<Mode>()
                .unwrap_err()
                .to_string()
                .contains("realtime or lockstep")
        );
        assert_eq!(Mode::Lockstep.delivery(), Delivery::Lossless);
        assert_eq!(Mode::Realtime.delivery(), Delivery::DropWhenFull);
    }

    #[test]
    fn seconds_from_nanoseconds_are_exact_on_the_grid() {
        assert_eq!(ns_to_s(1_000_000), 1e-3);
        assert_eq!(ns_to_s(20_000_000_000), 20.0);
    }
}
