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

/// Declares every parameter once: its documentation, serde attributes,
/// type, default and check. The struct, its `Default`, the range checks,
/// [`ControllerParams::KEYS`], [`ControllerParams::changed_keys`] and what
/// [`ControllerParams::for_law`] carries are all made from this one list.
macro_rules! parameters {
    ($(
        $(#[$meta:meta])*
        $field:ident : $ty:ty = $default:expr, $check:path;
    )*) => {
        /// Every parameter of the law. Unset keys take the paper's values.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct ControllerParams {
            $( $(#[$meta])* pub $field: $ty, )*
        }

        impl Default for ControllerParams {
            fn default() -> Self {
                Self { $( $field: $default, )* }
            }
        }

        impl ControllerParams {
            /// Every key of `[controller]`, in the order a scenario lists them.
            pub const KEYS: &'static [&'static str] = &[$( stringify!($field) ),*];

            /// Every key whose value differs from its default.
            pub fn changed_keys(&self) -> Vec<&'static str> {
                let d = Self::default();
                let mut out = Vec::new();
                $( if self.$field != d.$field { out.push(stringify!($field)); } )*
                out
            }

            /// Each key's own check; the error names it (`controller.<key>`).
            fn check_each(&self) -> Result<(), ControllerError> {
                $( $check(concat!("controller.", stringify!($field)), &self.$field)?; )*
                Ok(())
            }

            /// Copies from `other` every key `keep` accepts.
            fn carry(&mut self, other: &Self, keep: impl Fn(&str) -> bool) {
                $( if keep(stringify!($field)) { self.$field = other.$field.clone(); } )*
            }
        }
    };
}

parameters! {
    /// The law (default: "nac", the paper's). Every other key must be one
    /// the law takes ([`LawName::keys`]) or be left at its default.
    law: LawName = LawName::Nac, any;
    /// Prescribed time T_c at which the constraint is fully on (default: 2, s).
    tc: f64 = 2.0, positive;
    /// Position-error gain K1 = diag(K1_i): one number or one per joint
    /// (default: 15, 1/s; SPEC §7 needs K1_i > 0).
    k1: Gain = Gain::All(15.0), positive_gain;
    /// Velocity-error gain K2 = diag(K2_i): one number or one per joint
    /// (default: 15, N m s/rad; the analysis asks K2_i > 1/2, SPEC §7 allows
    /// less on very light joints and the testbed reports them).
    k2: Gain = Gain::All(15.0), positive_gain;
    /// Barrier steepness β (default: 10).
    beta: f64 = 10.0, positive;
    /// Actor learning rate σ_a (default: 50).
    sigma_a: f64 = 50.0, positive;
    /// Critic learning rate σ_c (default: 50).
    sigma_c: f64 = 50.0, positive;
    /// Actor regularisation η_a (default: 0.01).
    eta_a: f64 = 0.01, positive;
    /// Critic regularisation η_c (default: 0.5).
    eta_c: f64 = 0.5, positive;
    /// RBF neurons N in each network (default: 10; at most [`MAX_NEURONS`]).
    neurons: usize = 10, neuron_count;
    /// Smallest RBF centre c_min (default: -5).
    center_min: f64 = -5.0, finite;
    /// Largest RBF centre c_max (default: 5).
    center_max: f64 = 5.0, finite;
    /// RBF width η (default: 1).
    width: f64 = 1.0, positive;
    /// Where the centres lie (default: "diagonal", the paper's).
    rbf_layout: RbfLayout = RbfLayout::Diagonal, any;
    /// Young's-inequality weight a in α (default: 1).
    a: f64 = 1.0, positive;
    /// Critic discount time constant ψ (default: 1, s).
    psi: f64 = 1.0, positive;
    /// Critic-to-actor gain k_a (default: 0.1).
    k_a: f64 = 0.1, non_negative;
    /// Q = q_weight · I on Z_c = [Z1; Z2] (default: 1).
    q_weight: f64 = 1.0, non_negative;
    /// R = r_weight · I on τ (default: 0.01).
    r_weight: f64 = 0.01, non_negative;
    /// Weight integrator (default: "exact").
    integrator: Integrator = Integrator::Exact, any;
    /// Barrier mode (default: "per-joint").
    barrier: BarrierMode = BarrierMode::PerJoint, any;
    /// Guard ε: D is clamped to at least ε k_c² (default: 1e-6).
    breach_epsilon: f64 = 1e-6, open_unit;
    /// `pd-gravity`, `ctc`: every link's mass and inertia in the law's copy
    /// of the model is scaled by this (default: 1, the URDF's).
    model_scale: f64 = 1.0, positive;
    /// `ppc`: the final velocity-funnel width ρ2,∞ (default: 4, rad/s: the
    /// smallest power of two that keeps every shipped two-link scenario
    /// inside both funnels; 2 breaches under the 3 ms actuation delay).
    rho2_inf: f64 = 4.0, positive;
    /// `smc`: the switching gain k_s, N m (default: 2: the size of an
    /// unmodelled torque the law rejects inside its boundary layer, e.g.
    /// the paper arm's payload and friction).
    smc_gain: f64 = 2.0, non_negative;
    /// `smc`: the boundary layer's width φ on s = ė + K1 e, rad/s (default:
    /// 0.05: the switch is linear for |s| < φ, which keeps it from
    /// chattering at a 1 ms period).
    smc_boundary: f64 = 0.05, positive;
    /// `cbf-ctc`: the filter's rate λ, 1/s: h = k_c² − e² obeys
    /// ḧ + 2λ ḣ + λ² h ≥ 0, a double pole at −λ (default: 20).
    cbf_rate: f64 = 20.0, positive;
    /// `mpc`: prediction steps N (default: 10; with `mpc_step` a 0.1 s
    /// look-ahead for the envelope, 1.5 time constants of the default
    /// gains' error dynamics; beyond it the terminal cost is the infinite
    /// horizon's, so N sets only how far ahead the envelope is seen; at
    /// most [`MAX_MPC_HORIZON`]).
    mpc_horizon: usize = 10, horizon_steps;
    /// `mpc`: the prediction step h, s (default: 0.01: ten control periods
    /// at 1 kHz; the QP is still solved every period).
    mpc_step: f64 = 0.01, positive;
    /// `ctc`, `cbf-ctc`, `mpc`, `ppc`: how K1, K2 become the law's gains (default:
    /// "as-given"; "matched" matches `pd`'s error dynamics). Unwritten at
    /// its default so that existing scenarios keep their identity.
    #[serde(skip_serializing_if = "is_default")]
    tuning: Tuning = Tuning::AsGiven, any;
}

/// The most neurons a network may have: checked before anything is
/// allocated (the paper uses 10; the per-input layout has this many per
/// input, 4n inputs for the actor).
pub const MAX_NEURONS: usize = 1000;

/// The longest `mpc` horizon, in prediction steps: the QP grows with it
/// and must be solved within a control period.
pub const MAX_MPC_HORIZON: usize = 200;

/// The error for `key` = `value`, which must be `need`.
fn invalid(key: &str, value: impl ToString, need: impl Into<String>) -> ControllerError {
    ControllerError::InvalidParameter {
        key: key.to_string(),
        value: value.to_string(),
        need: need.into(),
    }
}

// The checks a parameter's declaration names; each fails NaN.

fn any<T>(_key: &str, _value: &T) -> Result<(), ControllerError> {
    Ok(())
}

fn positive(key: &str, v: &f64) -> Result<(), ControllerError> {
    match v.is_finite() && *v > 0.0 {
        true => Ok(()),
        false => Err(invalid(key, v, "a finite number > 0")),
    }
}

fn non_negative(key: &str, v: &f64) -> Result<(), ControllerError> {
    match v.is_finite() && *v >= 0.0 {
        true => Ok(()),
        false => Err(invalid(key, v, "a finite number ≥ 0")),
    }
}

fn open_unit(key: &str, v: &f64) -> Result<(), ControllerError> {
    match *v > 0.0 && *v < 1.0 {
        true => Ok(()),
        false => Err(invalid(key, v, "a number in (0, 1)")),
    }
}

fn finite(key: &str, v: &f64) -> Result<(), ControllerError> {
    match v.is_finite() {
        true => Ok(()),
        false => Err(invalid(key, v, "a finite number")),
    }
}

fn positive_gain(key: &str, g: &Gain) -> Result<(), ControllerError> {
    g.check_positive(key)
}

fn in_range(key: &str, v: usize, max: usize) -> Result<(), ControllerError> {
    match (1..=max).contains(&v) {
        true => Ok(()),
        false => Err(invalid(key, v, format!("from 1 to {max}"))),
    }
}

fn neuron_count(key: &str, v: &usize) -> Result<(), ControllerError> {
    in_range(key, *v, MAX_NEURONS)
}

fn horizon_steps(key: &str, v: &usize) -> Result<(), ControllerError> {
    in_range(key, *v, MAX_MPC_HORIZON)
}

impl ControllerParams {
    /// Checks every field; the error names the key (`controller.<key>`).
    pub fn validate(&self) -> Result<(), ControllerError> {
        self.check_each()?;
        self.check_keys_belong()?;
        if self.center_min > self.center_max {
            return Err(invalid(
                "controller.center_min",
                self.center_min,
                format!("≤ controller.center_max ({})", self.center_max),
            ));
        }
        Ok(())
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
            ..Self::default()
        };
        let shared = |key: &str| matches!(key, "tc" | "k1" | "k2");
        let both = |key: &str| key != "law" && law.takes(key) && self.law.takes(key);
        p.carry(self, |key| shared(key) || both(key));
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every key a law takes is declared, and every declared key is in the
    /// `[controller]` row of the scenario docs.
    #[test]
    fn every_key_is_declared_once_and_documented() {
        for law in LawName::ALL {
            for key in law.keys() {
                assert!(ControllerParams::KEYS.contains(&key), "{law}: {key}");
            }
        }
        let docs = include_str!("../../docs/scenarios-and-robots.md");
        let row = docs
            .lines()
            .find(|l| l.starts_with("| `[controller]` |"))
            .unwrap();
        for key in ControllerParams::KEYS {
            assert!(
                row.contains(&format!("`{key}`")),
                "{key} is not in the docs' [controller] row"
            );
        }
        // One key per field, each once.
        let mut keys = ControllerParams::KEYS.to_vec();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), ControllerParams::KEYS.len());
        let table: toml::Table =
            toml::from_str(&toml::to_string(&ControllerParams::default()).unwrap()).unwrap();
        // Written at its default: every key but `tuning` (unwritten so that
        // old scenarios keep their identity).
        assert_eq!(table.len(), ControllerParams::KEYS.len() - 1);
    }

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
