//! Controller parameters (SPEC §11), as read from a scenario's `[controller]` table.

use serde::{Deserialize, Serialize};

use crate::search_range::{GAIN_SCALE, Range, Role, SearchDim};
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
/// type, default, check and, for a key a tuner may search, its range and
/// role (`search (RANGE, ROLE)`, [`crate::search_space()`]). The struct, its `Default`, the range checks,
/// [`ControllerParams::KEYS`], [`ControllerParams::changed_keys`],
/// [`ControllerParams::SEARCH`] and what
/// [`ControllerParams::for_law`] carries are all made from this one list.
macro_rules! parameters {
    ($(
        $(#[doc = $doc:literal])*
        $(#[serde($($serde:tt)*)])*
        $field:ident : $ty:ty = $default:expr, $check:path $(, search $search:expr)?;
    )*) => {
        /// Every parameter of the law. Unset keys take the paper's values.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct ControllerParams {
            $( $(#[doc = $doc])* $(#[serde($($serde)*)])* pub $field: $ty, )*
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
                $( $check.run(concat!("controller.", stringify!($field)), &self.$field)?; )*
                Ok(())
            }

            /// The default of `key` as a scenario would write it (JSON).
            pub fn default_of(key: &str) -> Option<serde_json::Value> {
                let d = Self::default();
                match key {
                    $( stringify!($field) => serde_json::to_value(&d.$field).ok(), )*
                    _ => None,
                }
            }

            /// Every key as the parameter reference lists it
            /// (docs/generated/controller-parameters.md).
            pub const REFERENCE: &'static [ParamDoc] = &[$(ParamDoc {
                key: stringify!($field),
                doc: concat!($($doc, "\n"),*),
                need: $check.need,
            }),*];

            /// Every key a tuner may search, with its range (`search` in the
            /// declaration): [`crate::search_space()`] picks a law's from it.
            pub const SEARCH: &'static [SearchDim] = &[$($(SearchDim {
                key: stringify!($field),
                range: $search.0,
                role: $search.1,
            },)?)*];

            /// Copies from `other` every key `keep` accepts.
            fn carry(&mut self, other: &Self, keep: impl Fn(&str) -> bool) {
                $( if keep(stringify!($field)) { self.$field = other.$field.clone(); } )*
            }
        }
    };
}

parameters! {
    /// The law: "nac", the paper's, or a baseline of docs/baselines.md.
    /// Every other key must be one the law takes ([`LawName::keys`]) or be
    /// left at its default.
    law: LawName = LawName::Nac, ANY_NAME;
    /// Prescribed time T_c at which the constraint is fully on, s.
    tc: f64 = 2.0, TIME_CONSTANT;
    /// Position-error gain K1 = diag(K1_i), 1/s: one number or one per
    /// joint (SPEC §7 needs K1_i > 0).
    k1: Gain = Gain::All(15.0), POSITIVE_GAIN, search (GAIN_SCALE, Role::Gain);
    /// Velocity-error gain K2 = diag(K2_i), N m s/rad: one number or one
    /// per joint (the analysis asks K2_i > 1/2, SPEC §7 allows less on very
    /// light joints and the testbed reports them).
    k2: Gain = Gain::All(15.0), POSITIVE_GAIN, search (GAIN_SCALE, Role::Gain);
    /// Barrier steepness β.
    beta: f64 = 10.0, POSITIVE, search (Range::log(0.5, 100.0), Role::Law);
    /// Actor learning rate σ_a.
    sigma_a: f64 = 50.0, POSITIVE, search (Range::log(0.01, 1e4), Role::Actor);
    /// Critic learning rate σ_c.
    sigma_c: f64 = 50.0, POSITIVE, search (Range::log(0.01, 1e4), Role::Critic);
    /// Actor regularisation η_a.
    eta_a: f64 = 0.01, POSITIVE, search (Range::log(1e-5, 10.0), Role::Actor);
    /// Critic regularisation η_c.
    eta_c: f64 = 0.5, POSITIVE, search (Range::log(1e-5, 10.0), Role::Critic);
    /// RBF neurons N in each network (at most [`MAX_NEURONS`]).
    neurons: usize = 10, NEURON_COUNT, search (Range::int_log(2, 40), Role::Actor);
    /// Smallest RBF centre c_min (≤ `center_max`).
    center_min: f64 = -5.0, FINITE, search (Range::linear(-20.0, -0.1), Role::Actor);
    /// Largest RBF centre c_max.
    center_max: f64 = 5.0, FINITE, search (Range::linear(0.1, 20.0), Role::Actor);
    /// RBF width η.
    width: f64 = 1.0, POSITIVE, search (Range::log(0.05, 20.0), Role::Actor);
    /// Where the centres lie: "diagonal" (the paper's) or "per-input".
    rbf_layout: RbfLayout = RbfLayout::Diagonal, ANY_NAME,
        search (Range::choice(&["diagonal", "per-input"]), Role::Actor);
    /// Young's-inequality weight a in α.
    a: f64 = 1.0, POSITIVE, search (Range::log(0.1, 10.0), Role::Law);
    /// Critic discount time constant ψ, s.
    psi: f64 = 1.0, POSITIVE, search (Range::log(0.05, 20.0), Role::Critic);
    /// Critic-to-actor gain k_a.
    k_a: f64 = 0.1, NON_NEGATIVE, search (Range::log(1e-4, 10.0), Role::Critic);
    /// Q = q_weight · I on Z_c = [Z1; Z2].
    q_weight: f64 = 1.0, NON_NEGATIVE, search (Range::log(1e-3, 100.0), Role::Critic);
    /// R = r_weight · I on τ.
    r_weight: f64 = 0.01, NON_NEGATIVE, search (Range::log(1e-4, 1.0), Role::Critic);
    /// Weight integrator: "exact" or "euler" (SPEC §9).
    integrator: Integrator = Integrator::Exact, ANY_NAME;
    /// Barrier mode: "per-joint" or "norm" (SPEC §5).
    barrier: BarrierMode = BarrierMode::PerJoint, ANY_NAME;
    /// Guard ε: D is clamped to at least ε k_c² (SPEC §10).
    breach_epsilon: f64 = 1e-6, OPEN_UNIT;
    /// `pd-gravity`, `ctc`: every link's mass and inertia in the law's copy
    /// of the model is scaled by this (1: the URDF's).
    model_scale: f64 = 1.0, POSITIVE;
    /// `ppc`: the final velocity-funnel width ρ2,∞, rad/s (the default is
    /// the smallest power of two that keeps every shipped two-link scenario
    /// inside both funnels; half of it breaches under the 3 ms actuation
    /// delay).
    rho2_inf: f64 = 4.0, POSITIVE, search (Range::log(0.25, 64.0), Role::Law);
    /// `smc`: the switching gain k_s, N m: the size of an unmodelled torque
    /// the law rejects inside its boundary layer (the default covers the
    /// paper arm's payload and friction).
    smc_gain: f64 = 2.0, NON_NEGATIVE, search (Range::linear(0.0, 50.0), Role::Law);
    /// `smc`: the boundary layer's width φ on s = ė + K1 e, rad/s: the
    /// switch is linear for |s| < φ, which keeps it from chattering at a
    /// 1 ms period.
    smc_boundary: f64 = 0.05, POSITIVE, search (Range::log(1e-3, 1.0), Role::Law);
    /// `cbf-ctc`: the filter's rate λ, 1/s: h = k_c² − e² obeys
    /// ḧ + 2λ ḣ + λ² h ≥ 0, a double pole at −λ.
    cbf_rate: f64 = 20.0, POSITIVE, search (Range::log(1.0, 200.0), Role::Law);
    /// `cbf-ctc`: the robust margin δ, rad/s²: the bound on an unmodelled
    /// error acceleration |ë − u| ≤ δ the filter holds the envelope against
    /// (the condition is met for the worst such disturbance; 0: nominal).
    cbf_margin: f64 = 0.0, NON_NEGATIVE, search (Range::linear(0.0, 50.0), Role::Law);
    /// `cbf-ctc`, `mpc`: bound the torque by the URDF's effort limits
    /// (when every controlled joint has one), through the law's model:
    /// the error acceleration u is kept in a per-joint box whose every
    /// point gives |τ_i| ≤ effort_i at this step's M(q) (BASELINES §3).
    /// Off by default: the box is conservative (it can cut what the
    /// motors could give), so a bounded law loses seeds the plant's own
    /// clipping keeps, and the default rows compare the laws themselves.
    torque_bounds: bool = false, BOOLEAN;
    /// `mpc`: prediction steps N (at most [`MAX_MPC_HORIZON`]). The default,
    /// with `mpc_step`'s, looks 0.1 s ahead for the envelope, 1.5 time
    /// constants of the default gains' error dynamics; beyond it the
    /// terminal cost is the infinite horizon's, so N sets only how far
    /// ahead the envelope is seen.
    mpc_horizon: usize = 10, HORIZON_STEPS, search (Range::int_log(1, 50), Role::Law);
    /// `mpc`: the prediction step h, s (the default is ten control periods
    /// at 1 kHz; the QP is still solved every period).
    mpc_step: f64 = 0.01, MPC_STEP, search (Range::log(1e-3, 0.05), Role::Law);
    /// `mpc`: the disturbance bound w, rad/s², on the error dynamics
    /// ë = u + d, |d| ≤ w: the envelope and torque rows are tightened over
    /// the horizon by what such a d can do under the ancillary LQR
    /// feedback (tube MPC); 0: the nominal MPC.
    mpc_disturbance: f64 = 0.0, NON_NEGATIVE, search (Range::linear(0.0, 50.0), Role::Law);
    /// `ctc`, `cbf-ctc`, `mpc`, `ppc`: how K1, K2 become the law's gains:
    /// "as-given", or "matched" to `pd`'s error dynamics. Unwritten at its
    /// default so that existing scenarios keep their identity.
    #[serde(skip_serializing_if = "is_default")]
    tuning: Tuning = Tuning::AsGiven, ANY_NAME,
        search (Range::choice(&["as-given", "matched"]), Role::Law);
}

/// The longest prescribed time T_c, s ([`ControllerParams::tc`]).
pub const MAX_TC_S: f64 = 1e4;

pub use crate::gain::MAX_GAIN;

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

/// One key of `[controller]` as the reference page lists it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParamDoc {
    /// The key.
    pub key: &'static str,
    /// Its documentation, one line per doc-comment line.
    pub doc: &'static str,
    /// What its value must be.
    pub need: &'static str,
}

/// A parameter's check: what a value must be, said once for the error
/// and for the reference page, and the test of it.
pub struct Check<T: ?Sized> {
    /// What a value must be.
    pub need: &'static str,
    ok: fn(&T) -> bool,
}

impl<T: std::fmt::Debug + ?Sized> Check<T> {
    fn run(&self, key: &str, v: &T) -> Result<(), ControllerError> {
        match (self.ok)(v) {
            true => Ok(()),
            // Debug: 1e300 as written, not its 301 digits.
            false => Err(invalid(key, format!("{v:?}"), self.need)),
        }
    }
}

// The checks a parameter's declaration names; each fails NaN.

/// Any value serde accepts: a name, checked as it is read.
const ANY_NAME: AnyName = AnyName {
    need: "a name (see what it is)",
};
/// A switch: serde has read it as true or false.
const BOOLEAN: AnyName = AnyName {
    need: "true or false",
};
const POSITIVE: Check<f64> = Check {
    need: "a finite number > 0",
    ok: |v| v.is_finite() && *v > 0.0,
};
/// T_c: up to about three hours. Longer is not a prescribed time but a
/// constraint never switched on, and γ(t) then underflows every step.
const TIME_CONSTANT: Check<f64> = Check {
    need: "a time in (0, 10000] s",
    ok: |v| *v > 0.0 && *v <= MAX_TC_S,
};
/// The `mpc` prediction step: from 1 µs (below, the prediction matrices
/// lose every digit to rounding) to 10 s (beyond, e^{-K h} underflows).
const MPC_STEP: Check<f64> = Check {
    need: "a time from 1e-6 to 10 s",
    ok: |v| *v >= 1e-6 && *v <= 10.0,
};
const NON_NEGATIVE: Check<f64> = Check {
    need: "a finite number ≥ 0",
    ok: |v| v.is_finite() && *v >= 0.0,
};
const OPEN_UNIT: Check<f64> = Check {
    need: "a number in (0, 1)",
    ok: |v| *v > 0.0 && *v < 1.0,
};
const FINITE: Check<f64> = Check {
    need: "a finite number",
    ok: |v| v.is_finite(),
};
/// Gains say which joint's entry is wrong: [`Gain::check_positive`].
const POSITIVE_GAIN: GainCheck = GainCheck {
    need: "a number in (0, 1e6], or one per controlled joint, each in (0, 1e6]",
};
const NEURON_COUNT: Check<usize> = Check {
    need: "an integer from 1 to 1000 (MAX_NEURONS)",
    ok: |v| (1..=MAX_NEURONS).contains(v),
};
const HORIZON_STEPS: Check<usize> = Check {
    need: "an integer from 1 to 200 (MAX_MPC_HORIZON)",
    ok: |v| (1..=MAX_MPC_HORIZON).contains(v),
};

/// The check of a gain, whose error names the joint.
struct GainCheck {
    need: &'static str,
}

impl GainCheck {
    fn run(&self, key: &str, g: &Gain) -> Result<(), ControllerError> {
        g.check_positive(key)
    }
}

/// The check of a name (a law, a layout, …): serde has made it one.
struct AnyName {
    need: &'static str,
}

impl AnyName {
    fn run<T>(&self, _key: &str, _v: &T) -> Result<(), ControllerError> {
        Ok(())
    }
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

    /// Every key a law takes is declared, and documented: the reference
    /// page is made from the declarations (`params_reference.rs`, whose
    /// test keeps the shipped page current).
    #[test]
    fn every_key_is_declared_once_and_documented() {
        for law in LawName::ALL {
            for key in law.keys() {
                assert!(ControllerParams::KEYS.contains(&key), "{law}: {key}");
            }
        }
        for p in ControllerParams::REFERENCE {
            assert!(p.doc.trim().len() > 10, "{} has no documentation", p.key);
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
        let unwritten_at_default = 1;
        assert_eq!(
            table.len(),
            ControllerParams::KEYS.len() - unwritten_at_default
        );
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

    /// Issue 48 item 10 (N12): values that pass "finite and > 0" but fault
    /// on every step are refused up front, the error naming the key, the
    /// value and the range; the edges of each range are accepted.
    #[test]
    fn physically_absurd_values_are_refused_with_their_range() {
        let cases: [(&str, ControllerParams, &str); 6] = [
            (
                "controller.tc",
                ControllerParams {
                    tc: 1e300,
                    ..Default::default()
                },
                "(0, 10000] s",
            ),
            (
                "controller.mpc_step",
                ControllerParams {
                    law: LawName::Mpc,
                    mpc_step: 1e-300,
                    ..Default::default()
                },
                "from 1e-6 to 10 s",
            ),
            (
                "controller.mpc_step",
                ControllerParams {
                    law: LawName::Mpc,
                    mpc_step: 1e300,
                    ..Default::default()
                },
                "from 1e-6 to 10 s",
            ),
            (
                "controller.k1",
                ControllerParams {
                    k1: Gain::All(1e308),
                    ..Default::default()
                },
                "(0, 1e6]",
            ),
            (
                "controller.k2[1]",
                ControllerParams {
                    k2: Gain::Each(vec![1.0, 2e6]),
                    ..Default::default()
                },
                "(0, 1e6]",
            ),
            (
                "controller.k1",
                ControllerParams {
                    k1: Gain::All(f64::INFINITY),
                    ..Default::default()
                },
                "(0, 1e6]",
            ),
        ];
        for (key, p, range) in cases {
            let e = p.validate().unwrap_err().to_string();
            assert!(e.contains(key) && e.contains(range), "{key}: {e}");
        }
        let e = ControllerParams {
            tc: 1e300,
            ..Default::default()
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("1e300"), "the value is named: {e}");
        let edges = ControllerParams {
            law: LawName::Mpc,
            tc: 1e4,
            k1: Gain::All(1e6),
            k2: Gain::Each(vec![1e6, 1e-3]),
            mpc_step: 1e-6,
            ..Default::default()
        };
        edges.validate().unwrap();
        ControllerParams {
            law: LawName::Mpc,
            mpc_step: 10.0,
            ..Default::default()
        }
        .validate()
        .unwrap();
    }
}
