//! The vocabulary of a search space: a key's range, the part of a law it
//! tunes, and the gains' common range. The parameter table (`params.rs`)
//! declares each key's with these; `search_space.rs` picks a law's keys.

use serde::Serialize;

/// The range of one searchable key.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Range {
    /// A real number in [low, high], sampled uniformly or on a log scale.
    Float {
        /// Lowest value.
        low: f64,
        /// Highest value.
        high: f64,
        /// Sampled uniformly in log(value).
        log: bool,
    },
    /// An integer in [low, high].
    Int {
        /// Lowest value.
        low: i64,
        /// Highest value.
        high: i64,
        /// Sampled uniformly in log(value).
        log: bool,
    },
    /// A factor in [low, high] (log scale) on the scenario's own value,
    /// joint by joint: gains differ by orders of magnitude between arms and
    /// between a shoulder and a wrist, so one absolute range cannot fit them.
    Scale {
        /// Lowest factor.
        low: f64,
        /// Highest factor.
        high: f64,
    },
    /// One of the named values.
    Choice {
        /// The values, as a scenario writes them.
        choices: &'static [&'static str],
    },
}

impl Range {
    /// A real range sampled on a log scale.
    pub const fn log(low: f64, high: f64) -> Self {
        Self::Float {
            low,
            high,
            log: true,
        }
    }

    /// A real range sampled uniformly.
    pub const fn linear(low: f64, high: f64) -> Self {
        Self::Float {
            low,
            high,
            log: false,
        }
    }

    /// An integer range sampled on a log scale.
    pub const fn int_log(low: i64, high: i64) -> Self {
        Self::Int {
            low,
            high,
            log: true,
        }
    }

    /// A choice among named values.
    pub const fn choice(choices: &'static [&'static str]) -> Self {
        Self::Choice { choices }
    }

    /// The range as one line: `[0.01, 1e4] log`.
    pub fn describe(&self) -> String {
        let scale = |log: bool| if log { "log" } else { "linear" };
        match self {
            Range::Float { low, high, log } => format!("[{low}, {high}] {}", scale(*log)),
            Range::Int { low, high, log } => format!("integer [{low}, {high}] {}", scale(*log)),
            Range::Scale { low, high } => {
                format!("×[{low}, {high}] of the scenario's value, per joint, log")
            }
            Range::Choice { choices } => format!("one of {}", choices.join(", ")),
        }
    }
}

/// The gains' range: a sixteenth to four times the scenario's K1 (or K2).
/// The same for every law, so that no law is given more gain to spend.
pub const GAIN_SCALE: Range = Range::Scale {
    low: 0.0625,
    high: 4.0,
};

/// Which part of a law a key belongs to: a law's space leaves out the
/// parts it switches off, and the learning search keeps only the actor's
/// and the critic's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Role {
    /// K1, K2: every law's.
    Gain,
    /// The law's own shape (a barrier's β, a filter's rate, a horizon).
    Law,
    /// The actor network and the RBF features both networks use.
    Actor,
    /// The critic and its cost.
    Critic,
}

impl Role {
    /// Whether the key is one of the networks' (a learning knob).
    pub fn is_learning(self) -> bool {
        matches!(self, Role::Actor | Role::Critic)
    }
}

/// One searchable key.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SearchDim {
    /// The key under `[controller]`.
    pub key: &'static str,
    /// Its range.
    pub range: Range,
    /// The part of the law it tunes.
    pub role: Role,
}
