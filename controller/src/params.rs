//! Controller parameters (SPEC §11), as read from a scenario's `[controller]` table.

use serde::{Deserialize, Serialize};

use crate::{ControllerError, Gain, LawName};

/// How the weight ODEs are advanced over one control period (SPEC §9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Integrator {
    /// The exact solution with inputs held over the step; stable for any Δt.
    Exact,
    /// Explicit Euler, Ŵ ← Ŵ + Δt Ŵ̇: diverges on the paper's scenario (kept
    /// to show why the exact update is needed).
    Euler,
}

/// Which barrier the law uses (SPEC §5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BarrierMode {
    /// One barrier per joint with its own k_c,i (the paper's Section IV).
    PerJoint,
    /// One scalar bound k_c = min_i k_c,i and vector norms (Section III).
    Norm,
}

/// Where the RBF networks' centres lie (SPEC §8 and the option beside it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RbfLayout {
    /// The paper's: N centres c_j·1 on the diagonal of the input space.
    /// Far from every input once the state leaves the diagonal, so the
    /// actor stays nearly inert (SPEC §8).
    #[default]
    Diagonal,
    /// N one-dimensional neurons per input, centres spread over
    /// [center_min, center_max] and width `width` per input: every input
    /// value in the range has a neuron near it (N × inputs features).
    PerInput,
}

/// How `ctc`, `cbf-ctc`, `mpc` and `ppc` turn K1, K2 into their own gains (BASELINES.md §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Tuning {
    /// The textbook mapping: `ctc`, `cbf-ctc` and `mpc` poles at −K1, −K2; `ppc` k1 = K1, k2 = K2.
    #[default]
    AsGiven,
    /// The matching rule: each law's error dynamics near e = 0 are `pd`'s
    /// with the same K1, K2 on every joint (`ctc`: K_p' = K1 K2 / m_i,
    /// K_d' = K2 / m_i, m_i = 1 / (M⁻¹)_ii at the first reference posture,
    /// from the law's own model; `ppc`: k1 = K1 k_c(0) / 2,
    /// k2 = K2 ρ2,∞ / 2).
    Matched,
}

fn is_default<T: Default + PartialEq>(x: &T) -> bool {
    *x == T::default()
}

/// Every parameter of the law. Unset keys take the paper's values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ControllerParams {
    /// The law (default: "nac", the paper's). Every other key must be one
    /// the law takes ([`LawName::keys`]) or be left at its default.
    pub law: LawName,
    /// Prescribed time T_c at which the constraint is fully on (default: 2, s).
    pub tc: f64,
    /// Position-error gain K1 = diag(K1_i): one number or one per joint
    /// (default: 15, 1/s; SPEC §7 needs K1_i > 0).
    pub k1: Gain,
    /// Velocity-error gain K2 = diag(K2_i): one number or one per joint
    /// (default: 15, N m s/rad; the analysis asks K2_i > 1/2, SPEC §7 allows
    /// less on very light joints and the testbed reports them).
    pub k2: Gain,
    /// Barrier steepness β (default: 10).
    pub beta: f64,
    /// Actor learning rate σ_a (default: 50).
    pub sigma_a: f64,
    /// Critic learning rate σ_c (default: 50).
    pub sigma_c: f64,
    /// Actor regularisation η_a (default: 0.01).
    pub eta_a: f64,
    /// Critic regularisation η_c (default: 0.5).
    pub eta_c: f64,
    /// RBF neurons N in each network (default: 10).
    pub neurons: usize,
    /// Smallest RBF centre c_min (default: -5).
    pub center_min: f64,
    /// Largest RBF centre c_max (default: 5).
    pub center_max: f64,
    /// RBF width η (default: 1).
    pub width: f64,
    /// Where the centres lie (default: "diagonal", the paper's).
    pub rbf_layout: RbfLayout,
    /// Young's-inequality weight a in α (default: 1).
    pub a: f64,
    /// Critic discount time constant ψ (default: 1, s).
    pub psi: f64,
    /// Critic-to-actor gain k_a (default: 0.1).
    pub k_a: f64,
    /// Q = q_weight · I on Z_c = [Z1; Z2] (default: 1).
    pub q_weight: f64,
    /// R = r_weight · I on τ (default: 0.01).
    pub r_weight: f64,
    /// Weight integrator (default: "exact").
    pub integrator: Integrator,
    /// Barrier mode (default: "per-joint").
    pub barrier: BarrierMode,
    /// Guard ε: D is clamped to at least ε k_c² (default: 1e-6).
    pub breach_epsilon: f64,
    /// `pd-gravity`, `ctc`: every link's mass and inertia in the law's copy
    /// of the model is scaled by this (default: 1, the URDF's).
    pub model_scale: f64,
    /// `ppc`: the final velocity-funnel width ρ2,∞ (default: 4, rad/s: the
    /// smallest power of two that keeps every shipped two-link scenario
    /// inside both funnels; 2 breaches under the 3 ms actuation delay).
    pub rho2_inf: f64,
    /// `smc`: the switching gain k_s, N m (default: 2: the size of an
    /// unmodelled torque the law rejects inside its boundary layer, e.g.
    /// the paper arm's payload and friction).
    pub smc_gain: f64,
    /// `smc`: the boundary layer's width φ on s = ė + K1 e, rad/s (default:
    /// 0.05: the switch is linear for |s| < φ, which keeps it from
    /// chattering at a 1 ms period).
    pub smc_boundary: f64,
    /// `cbf-ctc`: the filter's rate λ, 1/s: h = k_c² − e² obeys
    /// ḧ + 2λ ḣ + λ² h ≥ 0, a double pole at −λ (default: 20).
    pub cbf_rate: f64,
    /// `mpc`: prediction steps N (default: 10; with `mpc_step` a 0.1 s
    /// look-ahead for the envelope, 1.5 time constants of the default
    /// gains' error dynamics; beyond it the terminal cost is the infinite
    /// horizon's, so N sets only how far ahead the envelope is seen).
    pub mpc_horizon: usize,
    /// `mpc`: the prediction step h, s (default: 0.01: ten control periods
    /// at 1 kHz; the QP is still solved every period).
    pub mpc_step: f64,
    /// `ctc`, `cbf-ctc`, `mpc`, `ppc`: how K1, K2 become the law's gains (default:
    /// "as-given"; "matched" matches `pd`'s error dynamics). Unwritten at
    /// its default so that existing scenarios keep their identity.
    #[serde(skip_serializing_if = "is_default")]
    pub tuning: Tuning,
}

impl Default for ControllerParams {
    fn default() -> Self {
        Self {
            law: LawName::Nac,
            tc: 2.0,
            k1: Gain::All(15.0),
            k2: Gain::All(15.0),
            beta: 10.0,
            sigma_a: 50.0,
            sigma_c: 50.0,
            eta_a: 0.01,
            eta_c: 0.5,
            neurons: 10,
            center_min: -5.0,
            center_max: 5.0,
            width: 1.0,
            rbf_layout: RbfLayout::Diagonal,
            a: 1.0,
            psi: 1.0,
            k_a: 0.1,
            q_weight: 1.0,
            r_weight: 0.01,
            integrator: Integrator::Exact,
            barrier: BarrierMode::PerJoint,
            breach_epsilon: 1e-6,
            model_scale: 1.0,
            rho2_inf: 4.0,
            smc_gain: 2.0,
            smc_boundary: 0.05,
            cbf_rate: 20.0,
            mpc_horizon: 10,
            mpc_step: 0.01,
            tuning: Tuning::AsGiven,
        }
    }
}

/// The most neurons a network may have: checked before anything is
/// allocated (the paper uses 10; the per-input layout has this many per
/// input, 4n inputs for the actor).
pub const MAX_NEURONS: usize = 1000;

/// The longest `mpc` horizon, in prediction steps: the QP grows with it
/// and must be solved within a control period.
pub const MAX_MPC_HORIZON: usize = 200;

/// What a value must satisfy; written so that NaN fails every check.
enum Bound {
    Positive,
    NonNegative,
    OpenUnit,
    Finite,
}

impl ControllerParams {
    /// Checks every field; the error names the key (`controller.<key>`).
    pub fn validate(&self) -> Result<(), ControllerError> {
        use Bound::*;
        self.k1.check_positive("controller.k1")?;
        self.k2.check_positive("controller.k2")?;
        let checks = [
            ("tc", self.tc, Positive),
            ("beta", self.beta, Positive),
            ("sigma_a", self.sigma_a, Positive),
            ("sigma_c", self.sigma_c, Positive),
            ("eta_a", self.eta_a, Positive),
            ("eta_c", self.eta_c, Positive),
            ("center_min", self.center_min, Finite),
            ("center_max", self.center_max, Finite),
            ("width", self.width, Positive),
            ("a", self.a, Positive),
            ("psi", self.psi, Positive),
            ("k_a", self.k_a, NonNegative),
            ("q_weight", self.q_weight, NonNegative),
            ("r_weight", self.r_weight, NonNegative),
            ("breach_epsilon", self.breach_epsilon, OpenUnit),
            ("model_scale", self.model_scale, Positive),
            ("rho2_inf", self.rho2_inf, Positive),
            ("smc_gain", self.smc_gain, NonNegative),
            ("smc_boundary", self.smc_boundary, Positive),
            ("cbf_rate", self.cbf_rate, Positive),
            ("mpc_step", self.mpc_step, Positive),
        ];
        for (key, value, bound) in checks {
            let (ok, need) = match bound {
                Positive => (
                    value.is_finite() && value > 0.0,
                    "a finite number > 0".to_string(),
                ),
                NonNegative => (
                    value.is_finite() && value >= 0.0,
                    "a finite number ≥ 0".to_string(),
                ),
                OpenUnit => (value > 0.0 && value < 1.0, "a number in (0, 1)".to_string()),
                Finite => (value.is_finite(), "a finite number".to_string()),
            };
            if !ok {
                return Err(ControllerError::InvalidParameter {
                    key: format!("controller.{key}"),
                    value: value.to_string(),
                    need,
                });
            }
        }
        if !(1..=MAX_NEURONS).contains(&self.neurons) {
            return Err(ControllerError::InvalidParameter {
                key: "controller.neurons".into(),
                value: self.neurons.to_string(),
                need: format!("from 1 to {MAX_NEURONS}"),
            });
        }
        if !(1..=MAX_MPC_HORIZON).contains(&self.mpc_horizon) {
            return Err(ControllerError::InvalidParameter {
                key: "controller.mpc_horizon".into(),
                value: self.mpc_horizon.to_string(),
                need: format!("from 1 to {MAX_MPC_HORIZON}"),
            });
        }
        self.check_keys_belong()?;
        if self.center_min > self.center_max {
            return Err(ControllerError::InvalidParameter {
                key: "controller.center_min".into(),
                value: self.center_min.to_string(),
                need: format!("≤ controller.center_max ({})", self.center_max),
            });
        }
        Ok(())
    }
}

impl ControllerParams {
    /// Every key whose value differs from its default.
    pub fn changed_keys(&self) -> Vec<&'static str> {
        let d = Self::default();
        let changed = [
            ("law", self.law != d.law),
            ("tc", self.tc != d.tc),
            ("k1", self.k1 != d.k1),
            ("k2", self.k2 != d.k2),
            ("beta", self.beta != d.beta),
            ("sigma_a", self.sigma_a != d.sigma_a),
            ("sigma_c", self.sigma_c != d.sigma_c),
            ("eta_a", self.eta_a != d.eta_a),
            ("eta_c", self.eta_c != d.eta_c),
            ("neurons", self.neurons != d.neurons),
            ("center_min", self.center_min != d.center_min),
            ("center_max", self.center_max != d.center_max),
            ("width", self.width != d.width),
            ("rbf_layout", self.rbf_layout != d.rbf_layout),
            ("a", self.a != d.a),
            ("psi", self.psi != d.psi),
            ("k_a", self.k_a != d.k_a),
            ("q_weight", self.q_weight != d.q_weight),
            ("r_weight", self.r_weight != d.r_weight),
            ("integrator", self.integrator != d.integrator),
            ("barrier", self.barrier != d.barrier),
            ("breach_epsilon", self.breach_epsilon != d.breach_epsilon),
            ("model_scale", self.model_scale != d.model_scale),
            ("rho2_inf", self.rho2_inf != d.rho2_inf),
            ("smc_gain", self.smc_gain != d.smc_gain),
            ("smc_boundary", self.smc_boundary != d.smc_boundary),
            ("cbf_rate", self.cbf_rate != d.cbf_rate),
            ("mpc_horizon", self.mpc_horizon != d.mpc_horizon),
            ("mpc_step", self.mpc_step != d.mpc_step),
            ("tuning", self.tuning != d.tuning),
        ];
        changed
            .iter()
            .filter(|(_, c)| *c)
            .map(|(k, _)| *k)
            .collect()
    }

    /// A key set away from its default that the chosen law does not take
    /// is an error naming it (a value that would silently do nothing).
    fn check_keys_belong(&self) -> Result<(), ControllerError> {
        match self.changed_keys().into_iter().find(|k| !self.law.takes(k)) {
            Some(key) => Err(ControllerError::NotAParameter {
                key: format!("controller.{key}"),
                law: self.law,
                takes: self.law.keys().join(", "),
            }),
            None => Ok(()),
        }
    }

    /// The same run's parameters for `law`: the keys every law shares (T_c,
    /// K1, K2) and those both laws take are kept, the rest go back to their
    /// defaults. This is how `compare` matches every law to one scenario.
    pub fn for_law(&self, law: LawName) -> Self {
        let mut p = Self {
            law,
            tc: self.tc,
            k1: self.k1.clone(),
            k2: self.k2.clone(),
            ..Self::default()
        };
        let keep = |key: &str| law.takes(key) && self.law.takes(key);
        macro_rules! carry {
            ($($field:ident),*) => {
                $(if keep(stringify!($field)) { p.$field = self.$field.clone(); })*
            };
        }
        carry!(
            beta,
            sigma_a,
            sigma_c,
            eta_a,
            eta_c,
            neurons,
            center_min,
            center_max,
            width,
            rbf_layout,
            a,
            psi,
            k_a,
            q_weight,
            r_weight,
            integrator,
            barrier,
            breach_epsilon,
            model_scale,
            rho2_inf,
            smc_gain,
            smc_boundary,
            cbf_rate,
            mpc_horizon,
            mpc_step,
            tuning
        );
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_papers_and_valid() {
        let p = ControllerParams::default();
        p.validate().unwrap();
        assert_eq!((p.tc, p.beta), (2.0, 10.0));
        assert_eq!((&p.k1, &p.k2), (&Gain::All(15.0), &Gain::All(15.0)));
        assert_eq!(
            (p.sigma_a, p.sigma_c, p.eta_a, p.eta_c),
            (50.0, 50.0, 0.01, 0.5)
        );
        assert_eq!(
            (p.neurons, p.center_min, p.center_max, p.width),
            (10, -5.0, 5.0, 1.0)
        );
    }

    #[test]
    fn a_key_the_law_does_not_take_is_named() {
        let p = ControllerParams {
            law: LawName::Pd,
            beta: 5.0,
            ..Default::default()
        };
        let e = p.validate().unwrap_err().to_string();
        assert!(
            e.contains("controller.beta") && e.contains("law 'pd'") && e.contains("tc, k1, k2"),
            "{e}"
        );
        // Left at its default, a key of another law is no error.
        let p = ControllerParams {
            law: LawName::Pd,
            ..Default::default()
        };
        p.validate().unwrap();
        let p = ControllerParams {
            law: LawName::Ctc,
            model_scale: 0.8,
            ..Default::default()
        };
        p.validate().unwrap();
    }

    #[test]
    fn for_law_keeps_shared_keys_and_resets_the_others() {
        let nac = ControllerParams {
            k1: Gain::Each(vec![20.0, 30.0]),
            tc: 1.5,
            beta: 4.0,
            ..Default::default()
        };
        let pd = nac.for_law(LawName::Pd);
        assert_eq!((pd.law, pd.tc, &pd.k1), (LawName::Pd, 1.5, &nac.k1));
        assert_eq!(pd.beta, 10.0);
        pd.validate().unwrap();
        assert_eq!(nac.for_law(LawName::NacNoShift).beta, 4.0);
        assert_eq!(pd.for_law(LawName::Nac).beta, 10.0);
    }

    #[test]
    fn nan_and_out_of_range_name_the_key() {
        let p = ControllerParams {
            beta: f64::NAN,
            ..Default::default()
        };
        assert!(
            p.validate()
                .unwrap_err()
                .to_string()
                .contains("controller.beta")
        );
        let p = ControllerParams {
            k1: Gain::Each(vec![1.0, 0.0]),
            ..Default::default()
        };
        assert!(
            p.validate()
                .unwrap_err()
                .to_string()
                .contains("controller.k1[1]")
        );
        let p = ControllerParams {
            breach_epsilon: f64::NAN,
            ..Default::default()
        };
        assert!(
            p.validate()
                .unwrap_err()
                .to_string()
                .contains("controller.breach_epsilon")
        );
        let p = ControllerParams {
            center_min: 6.0,
            ..Default::default()
        };
        assert!(
            p.validate()
                .unwrap_err()
                .to_string()
                .contains("controller.center_min")
        );
        for neurons in [0, MAX_NEURONS + 1, usize::MAX] {
            let p = ControllerParams {
                neurons,
                ..Default::default()
            };
            let e = p.validate().unwrap_err().to_string();
            assert!(
                e.contains("controller.neurons") && e.contains("from 1 to 1000"),
                "{e}"
            );
        }
    }
}
