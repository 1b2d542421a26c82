//! A diagonal gain matrix as a scenario writes it (SPEC §7): one number for
//! every joint, or one per joint.

use serde::{Deserialize, Serialize};

use crate::ControllerError;

/// The largest gain K1_i, K2_i: a million times the paper's order of
/// magnitude is far past any real arm's and still leaves K e and K ė finite
/// for any error the envelope allows. Declared beside [`Gain`], which checks
/// it, so that the parameters' module imports this one and not the reverse.
pub const MAX_GAIN: f64 = 1e6;

/// K = diag(K_i): one number for every joint, or one per joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a number, or a list of numbers with one per controlled joint"
)]
pub enum Gain {
    /// The same K_i for every joint (the paper's form).
    All(f64),
    /// One K_i per controlled joint, in joint order.
    Each(Vec<f64>),
}

impl From<f64> for Gain {
    fn from(v: f64) -> Self {
        Self::All(v)
    }
}

impl Gain {
    /// The entries as written (one for `All`).
    pub fn entries(&self) -> &[f64] {
        match self {
            Self::All(x) => std::slice::from_ref(x),
            Self::Each(v) => v,
        }
    }

    /// K_i for an arm of `n` joints; `key` names the gain in errors.
    pub fn resolve(&self, key: &str, n: usize) -> Result<Vec<f64>, ControllerError> {
        match self {
            Self::All(x) => Ok(vec![*x; n]),
            Self::Each(v) if v.len() == n => Ok(v.clone()),
            Self::Each(v) => Err(ControllerError::InvalidParameter {
                key: key.to_string(),
                value: format!("{} entries", v.len()),
                need: format!("one number, or one per controlled joint ({n})"),
            }),
        }
    }

    /// Checks every entry is in (0, [`MAX_GAIN`]] (written so NaN
    /// fails): a gain of 1e308 passed "finite and > 0" and then faulted on
    /// every step.
    pub(crate) fn check_positive(&self, key: &str) -> Result<(), ControllerError> {
        let bad = |k: String, v: f64| ControllerError::InvalidParameter {
            key: k,
            value: format!("{v:?}"),
            need: "a number in (0, 1e6]".into(),
        };
        let ok = |x: &f64| *x > 0.0 && *x <= MAX_GAIN;
        match self {
            Self::All(x) if !ok(x) => Err(bad(key.to_string(), *x)),
            Self::Each(v) if v.is_empty() => Err(ControllerError::InvalidParameter {
                key: key.to_string(),
                value: "[]".into(),
                need: "one number, or one per controlled joint".into(),
            }),
            Self::Each(v) => match v.iter().position(|x| !ok(x)) {
                Some(i) => Err(bad(format!("{key}[{i}]"), v[i])),
                None => Ok(()),
            },
            Self::All(_) => Ok(()),
        }
    }
}

impl std::fmt::Display for Gain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::All(x) => write!(f, "{x}"),
            Self::Each(v) => {
                let s: Vec<String> = v.iter().map(|x| format!("{x:.4}")).collect();
                write!(f, "[{}]", s.join(", "))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;

    /// A value of neither form says what a gain is, not serde's "no
    /// variant of untagged enum".
    #[test]
    fn a_value_of_neither_form_says_what_a_gain_is() {
        #[derive(Debug, serde::Deserialize)]
        struct T {
            #[allow(dead_code, reason = "only its parse error is read")]
            k: Gain,
        }
        let e = toml::from_str::<T>("k = \"[1,\"").unwrap_err().to_string();
        assert!(
            e.contains("a number, or a list of numbers with one per controlled joint"),
            "{e}"
        );
        assert!(toml::from_str::<T>("k = 20").is_ok());
        assert!(toml::from_str::<T>("k = [1.0, 2]").is_ok());
    }

    #[test]
    fn one_number_or_one_per_joint() {
        assert_eq!(Gain::All(2.0).resolve("k", 3).unwrap(), [2.0; 3]);
        assert_eq!(
            Gain::Each(vec![1.0, 2.0]).resolve("k", 2).unwrap(),
            [1.0, 2.0]
        );
        let e = Gain::Each(vec![1.0])
            .resolve("controller.k2", 2)
            .unwrap_err();
        assert!(e.to_string().contains("controller.k2 = 1 entries"), "{e}");
    }

    #[test]
    fn nan_zero_and_empty_are_refused_by_index() {
        let e = Gain::Each(vec![1.0, f64::NAN]).check_positive("controller.k1");
        assert!(
            e.unwrap_err()
                .to_string()
                .contains("controller.k1[1] = NaN")
        );
        assert!(Gain::All(0.0).check_positive("k").is_err());
        assert!(Gain::Each(vec![]).check_positive("k").is_err());
        assert!(Gain::Each(vec![0.3, 15.0]).check_positive("k").is_ok());
    }

    #[test]
    fn toml_reads_a_number_or_a_list() {
        #[derive(Deserialize)]
        struct T {
            k: Gain,
        }
        let t: T = toml::from_str("k = 15.0").unwrap();
        assert_eq!(t.k, Gain::All(15.0));
        let t: T = toml::from_str("k = [1.0, 2.5]").unwrap();
        assert_eq!(t.k, Gain::Each(vec![1.0, 2.5]));
    }
}
