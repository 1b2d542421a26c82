//! What a tuner may search for each law: every searchable `[controller]` key
//! with its range, declared beside the key itself in the parameter table
//! (`search` in `params.rs`), and the part of it each law takes.
//!
//! One space serves every law, so that a comparison of tuned laws gives each
//! the same ranges for the keys they share (the gains above all) and the same
//! budget of trials (`testbed tune`, docs/tuning.md). A law's space is the
//! keys it takes ([`LawName::takes`]) that have a range, less the knobs of
//! parts it switches off (an ablation without networks has no learning knobs
//! to search: they would change nothing).

use serde::Serialize;

use crate::{ControllerParams, LawKind, LawName};

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

/// The keys a tuner searches for `law`, in the parameter table's order.
pub fn search_space(law: LawName) -> Vec<SearchDim> {
    ControllerParams::SEARCH
        .iter()
        .filter(|d| law.takes(d.key) && law_uses(law, d.role))
        .copied()
        .collect()
}

/// Whether `law` runs the part that `role` tunes.
fn law_uses(law: LawName, role: Role) -> bool {
    match (law.decl().kind, role) {
        (_, Role::Gain | Role::Law) => true,
        (LawKind::Barrier(parts), Role::Actor) => parts.networks,
        (LawKind::Barrier(parts), Role::Critic) => parts.networks && parts.critic,
        (LawKind::Feedback(_) | LawKind::Ppc, Role::Actor | Role::Critic) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_searched_key_is_a_key_and_its_default_lies_in_its_range() {
        let d = ControllerParams::default();
        let defaults = serde_json::to_value(&d).unwrap();
        for dim in ControllerParams::SEARCH {
            assert!(ControllerParams::KEYS.contains(&dim.key), "{}", dim.key);
            let v = &defaults[dim.key];
            match dim.range {
                Range::Float { low, high, log } => {
                    let x = v.as_f64().unwrap();
                    assert!(low < high && (!log || low > 0.0), "{}", dim.key);
                    // A default outside (cbf_margin's 0 on a linear range is
                    // inside) would mean the paper's value cannot be tried.
                    assert!((low..=high).contains(&x), "{} = {x}", dim.key);
                }
                Range::Int { low, high, .. } => {
                    let x = v.as_i64().unwrap();
                    assert!((low..=high).contains(&x), "{} = {x}", dim.key);
                }
                Range::Scale { low, high } => assert!(low < 1.0 && high > 1.0),
                Range::Choice { choices } => {
                    assert!(choices.contains(&v.as_str().unwrap()), "{}", dim.key)
                }
            }
        }
    }

    #[test]
    fn a_choice_reads_as_the_key_reads() {
        for dim in ControllerParams::SEARCH {
            if let Range::Choice { choices } = dim.range {
                for c in choices {
                    let text = format!("law = \"{}\"\n{} = \"{c}\"", law_of(dim.key), dim.key);
                    let p: ControllerParams = toml::from_str(&text).unwrap();
                    p.validate().unwrap();
                }
            }
        }
    }

    fn law_of(key: &str) -> &'static str {
        LawName::ALL
            .iter()
            .find(|l| l.takes(key))
            .map(|l| l.decl().name)
            .unwrap()
    }

    #[test]
    fn ablations_search_only_what_they_run() {
        let keys = |l| search_space(l).iter().map(|d| d.key).collect::<Vec<_>>();
        assert!(keys(LawName::Nac).contains(&"sigma_a"));
        assert!(keys(LawName::Nac).contains(&"k_a"));
        assert!(keys(LawName::NacNoCritic).contains(&"sigma_a"));
        assert!(!keys(LawName::NacNoCritic).contains(&"sigma_c"));
        assert!(!keys(LawName::NacNoNetworks).contains(&"sigma_a"));
        assert!(keys(LawName::NacNoNetworks).contains(&"beta"));
        assert_eq!(keys(LawName::Pd), ["k1", "k2"]);
        assert!(keys(LawName::Mpc).contains(&"mpc_horizon"));
        assert!(keys(LawName::CbfCtc).contains(&"cbf_margin"));
        // Every law can be tuned: its gains at least.
        for &l in LawName::ALL {
            assert!(keys(l).starts_with(&["k1", "k2"]), "{l:?}");
        }
    }
}
