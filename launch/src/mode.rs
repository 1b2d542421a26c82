//! How the processes of a run keep time.

use serde::Serialize;

/// Timing mode of a multi-process run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
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
    /// The command-line spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Realtime => "realtime",
            Mode::Lockstep => "lockstep",
        }
    }
}

impl From<Mode> for wire::Mode {
    fn from(m: Mode) -> Self {
        match m {
            Mode::Realtime => wire::Mode::Realtime,
            Mode::Lockstep => wire::Mode::Lockstep,
        }
    }
}
