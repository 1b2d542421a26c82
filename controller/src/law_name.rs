//! The laws a run can use (BASELINES.md) and the scenario keys each takes.

use serde::{Deserialize, Serialize};

/// Which control law the controller runs (`[controller] law`, `--law`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LawName {
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
}

/// Keys every law takes.
const COMMON: &[&str] = &["law", "tc", "k1", "k2"];
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

impl LawName {
    /// Every law, in the order `compare` lists them.
    pub const ALL: [LawName; 9] = [
        LawName::Nac,
        LawName::NacNoShift,
        LawName::NacNoCritic,
        LawName::NacNoNetworks,
        LawName::Blf,
        LawName::Pd,
        LawName::PdGravity,
        LawName::Ctc,
        LawName::Ppc,
    ];

    /// The name as a scenario and the CLI write it.
    pub fn as_str(self) -> &'static str {
        match self {
            LawName::Nac => "nac",
            LawName::NacNoShift => "nac-no-shift",
            LawName::NacNoCritic => "nac-no-critic",
            LawName::NacNoNetworks => "nac-no-networks",
            LawName::Blf => "blf",
            LawName::Pd => "pd",
            LawName::PdGravity => "pd-gravity",
            LawName::Ctc => "ctc",
            LawName::Ppc => "ppc",
        }
    }

    /// Whether the law uses the arm's model (M, C, G from the URDF).
    pub fn model_based(self) -> bool {
        matches!(self, LawName::PdGravity | LawName::Ctc)
    }

    /// Whether the law is the paper's or one of its ablations.
    pub fn is_nac(self) -> bool {
        matches!(
            self,
            LawName::Nac | LawName::NacNoShift | LawName::NacNoCritic | LawName::NacNoNetworks
        )
    }

    /// Whether `key` (of `[controller]`) is a parameter of this law.
    pub fn takes(self, key: &str) -> bool {
        COMMON.contains(&key)
            || match self {
                _ if self.is_nac() => NAC.contains(&key),
                LawName::Blf => matches!(key, "barrier" | "breach_epsilon"),
                LawName::PdGravity | LawName::Ctc => key == "model_scale",
                LawName::Ppc => key == "rho2_inf",
                _ => false,
            }
    }

    /// The keys this law takes, for messages.
    pub fn keys(self) -> Vec<&'static str> {
        let all = COMMON.iter().chain(NAC).chain(&["model_scale", "rho2_inf"]);
        all.copied().filter(|k| self.takes(k)).collect()
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
            .into_iter()
            .find(|l| l.as_str() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = LawName::ALL.iter().map(|l| l.as_str()).collect();
                format!("unknown law '{s}'; the laws are {}", names.join(", "))
            })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn names_round_trip_through_text_and_serde() {
        for law in LawName::ALL {
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
