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

use crate::search_range::{Role, SearchDim};
use crate::{ControllerParams, LawKind, LawName};

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
    use crate::search_range::Range;

    #[test]
    fn every_searched_key_is_a_key_and_its_default_lies_in_its_range() {
        for dim in ControllerParams::SEARCH {
            assert!(ControllerParams::KEYS.contains(&dim.key), "{}", dim.key);
            // The field alone: a key unwritten at its default (tuning) is
            // absent from the serialised struct.
            let v = ControllerParams::default_of(dim.key).unwrap();
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
