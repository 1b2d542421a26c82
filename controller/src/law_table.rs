//! The laws a run can use (BASELINES.md) and the scenario keys each takes.

use serde::{Deserialize, Serialize};

/// Declares [`LawName`] and [`LawName::ALL`] from one list of variants, so
/// the list of laws cannot miss one.
macro_rules! law_names {
    ($( $(#[$doc:meta])* $variant:ident ),* $(,)?) => {
        /// Which control law the controller runs (`[controller] law`, `--law`).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
        #[serde(rename_all = "kebab-case")]
        pub enum LawName {
            $( $(#[$doc])* $variant, )*
        }

        impl LawName {
            /// Every law, in the order `compare` lists them.
            pub const ALL: &'static [LawName] = &[$(LawName::$variant),*];
        }
    };
}

law_names! {
    /// The paper's law (SPEC).
    #[default]
    Nac,
    /// γ ≡ 1: the constraint is on from t = 0.
    NacNoShift,
    /// Ĵ ≡ 0, the critic is not updated.
    NacNoCritic,
    /// Actor output ≡ 0, no weight updates.
    NacNoNetworks,
    /// Classic log-barrier backstepping: β = 1, γ ≡ 1, no networks.
    Blf,
    /// τ = −K1K2 e − K2 ė.
    Pd,
    /// τ = G(q) − K1K2 e − K2 ė (model-based).
    PdGravity,
    /// Computed torque with poles at −K1, −K2 (model-based).
    Ctc,
    /// Low-complexity prescribed performance control.
    Ppc,
    /// Sliding mode control with a boundary layer (model-free).
    Smc,
    /// Computed torque through a CBF–QP safety filter on |e| < k_c (model-based).
    CbfCtc,
    /// Constrained linear MPC on the error dynamics, |e| ≤ k_c (model-based).
    Mpc,
}

/// Which parts of the paper's law run (its ablations and `blf` switch
/// some off).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BarrierParts {
    /// The shifting function γ(t); off: γ ≡ 1.
    pub shift: bool,
    /// The actor and its update; off: actor output ≡ 0.
    pub networks: bool,
    /// The critic; off: Ĵ ≡ 0, critic not updated.
    pub critic: bool,
    /// The classic log barrier (β = 1) instead of the scenario's β.
    pub classic_barrier: bool,
}

/// The linear feedback laws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeedbackKind {
    /// `pd`.
    Pd,
    /// `pd-gravity` (model-based).
    PdGravity,
    /// `ctc` (model-based).
    Ctc,
    /// `smc`: sliding mode with a boundary layer (model-free).
    Smc,
    /// `cbf-ctc`: `ctc` through a control-barrier-function filter
    /// (model-based).
    CbfCtc,
    /// `mpc`: computed torque whose error input comes from a constrained
    /// linear MPC (model-based).
    Mpc,
}

/// How a law is built and stepped. Every choice between laws goes through
/// [`LawName::decl`], whose match is exhaustive: a law added to
/// [`LawName`] does not compile until it is declared, and never runs
/// another law's code by default.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LawKind {
    /// The paper's law with the given parts (`nac`, its ablations, `blf`).
    Barrier(BarrierParts),
    /// `pd`, `pd-gravity`, `ctc`.
    Feedback(FeedbackKind),
    /// `ppc`.
    Ppc,
}

/// One law's declaration: its name, how it is built, and the scenario keys
/// it takes beyond the common ones.
#[derive(Debug, Clone, Copy)]
pub struct LawDecl {
    /// The name as a scenario and the CLI write it.
    pub name: &'static str,
    /// How it is built and stepped.
    pub kind: LawKind,
    /// Its own `[controller]` keys beyond `COMMON`.
    pub keys: &'static [&'static str],
}

/// Keys every law takes.
pub const COMMON: &[&str] = &["law", "tc", "k1", "k2"];
/// Keys of the paper's law beyond [`COMMON`]; its ablations take them all,
/// so that one scenario serves all four.
const NAC: &[&str] = &[
    "beta",
    "sigma_a",
    "sigma_c",
    "eta_a",
    "eta_c",
    "neurons",
    "center_min",
    "center_max",
    "width",
    "rbf_layout",
    "a",
    "psi",
    "k_a",
    "q_weight",
    "r_weight",
    "integrator",
    "barrier",
    "breach_epsilon",
];

const PAPER: BarrierParts = BarrierParts {
    shift: true,
    networks: true,
    critic: true,
    classic_barrier: false,
};

impl LawName {
    /// The law's one declaration.
    pub const fn decl(self) -> LawDecl {
        match self {
            LawName::Nac => LawDecl {
                name: "nac",
                kind: LawKind::Barrier(PAPER),
                keys: NAC,
            },
            LawName::NacNoShift => LawDecl {
                name: "nac-no-shift",
                kind: LawKind::Barrier(BarrierParts {
                    shift: false,
                    ..PAPER
                }),
                keys: NAC,
            },
            LawName::NacNoCritic => LawDecl {
                name: "nac-no-critic",
                kind: LawKind::Barrier(BarrierParts {
                    critic: false,
                    ..PAPER
                }),
                keys: NAC,
            },
            LawName::NacNoNetworks => LawDecl {
                name: "nac-no-networks",
                kind: LawKind::Barrier(BarrierParts {
                    networks: false,
                    critic: false,
                    ..PAPER
                }),
                keys: NAC,
            },
            LawName::Blf => LawDecl {
                name: "blf",
                kind: LawKind::Barrier(BarrierParts {
                    shift: false,
                    networks: false,
                    critic: false,
                    classic_barrier: true,
                }),
                keys: &["barrier", "breach_epsilon"],
            },
            LawName::Pd => LawDecl {
                name: "pd",
                kind: LawKind::Feedback(FeedbackKind::Pd),
                keys: &[],
            },
            LawName::PdGravity => LawDecl {
                name: "pd-gravity",
                kind: LawKind::Feedback(FeedbackKind::PdGravity),
                keys: &["model_scale"],
            },
            LawName::Ctc => LawDecl {
                name: "ctc",
                kind: LawKind::Feedback(FeedbackKind::Ctc),
                keys: &["model_scale", "tuning"],
            },
            LawName::Ppc => LawDecl {
                name: "ppc",
                kind: LawKind::Ppc,
                keys: &["rho2_inf", "tuning"],
            },
            LawName::Smc => LawDecl {
                name: "smc",
                kind: LawKind::Feedback(FeedbackKind::Smc),
                keys: &["smc_gain", "smc_boundary"],
            },
            LawName::CbfCtc => LawDecl {
                name: "cbf-ctc",
                kind: LawKind::Feedback(FeedbackKind::CbfCtc),
                keys: &[
                    "model_scale",
                    "tuning",
                    "cbf_rate",
                    "cbf_margin",
                    "torque_bounds",
                ],
            },
            LawName::Mpc => LawDecl {
                name: "mpc",
                kind: LawKind::Feedback(FeedbackKind::Mpc),
                keys: &[
                    "model_scale",
                    "tuning",
                    "mpc_horizon",
                    "mpc_step",
                    "mpc_disturbance",
                    "torque_bounds",
                ],
            },
        }
    }

    /// How the law is built and stepped.
    pub const fn kind(self) -> LawKind {
        self.decl().kind
    }

    /// The name as a scenario and the CLI write it.
    pub const fn as_str(self) -> &'static str {
        self.decl().name
    }

    /// Whether the law uses the arm's model (M, C, G from the URDF).
    pub fn model_based(self) -> bool {
        matches!(
            self.kind(),
            LawKind::Feedback(
                FeedbackKind::PdGravity
                    | FeedbackKind::Ctc
                    | FeedbackKind::CbfCtc
                    | FeedbackKind::Mpc
            )
        )
    }

    /// Whether `key` (of `[controller]`) is a parameter of this law.
    pub fn takes(self, key: &str) -> bool {
        COMMON.contains(&key) || self.decl().keys.contains(&key)
    }

    /// The keys this law takes, for messages (in the order of the
    /// scenario file).
    pub fn keys(self) -> Vec<&'static str> {
        let mut all: Vec<&'static str> = COMMON.to_vec();
        for law in LawName::ALL {
            for k in law.decl().keys {
                if !all.contains(k) {
                    all.push(k);
                }
            }
        }
        all.into_iter().filter(|k| self.takes(k)).collect()
    }
}

impl std::fmt::Display for LawName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for LawName {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        LawName::ALL
            .iter()
            .copied()
            .find(|l| l.as_str() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = LawName::ALL.iter().map(|l| l.as_str()).collect();
                format!("unknown law '{s}'; the laws are {}", names.join(", "))
            })
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    #[test]
    fn names_round_trip_through_text_and_serde() {
        for &law in LawName::ALL {
            assert_eq!(law.as_str().parse::<LawName>().unwrap(), law);
            let json = serde_json::to_string(&law).unwrap();
            assert_eq!(json, format!("\"{law}\""));
        }
        let e = "nac2".parse::<LawName>().unwrap_err();
        assert!(e.contains("unknown law 'nac2'") && e.contains("ppc"), "{e}");
    }

    #[test]
    fn each_law_takes_its_own_keys_only() {
        assert!(LawName::Nac.takes("beta") && !LawName::Nac.takes("model_scale"));
        assert!(LawName::NacNoNetworks.takes("neurons"));
        assert!(LawName::Blf.takes("breach_epsilon") && !LawName::Blf.takes("beta"));
        assert_eq!(LawName::Pd.keys(), ["law", "tc", "k1", "k2"]);
        assert!(LawName::Ctc.takes("model_scale") && !LawName::Pd.takes("model_scale"));
        assert!(LawName::Ppc.takes("rho2_inf") && !LawName::Ppc.takes("k_a"));
    }
}
