//! Per-joint settings: one number for every joint or one per joint,
//! checked and resolved against the arm's joint count.

use serde::{Deserialize, Serialize};

use super::{invalid, short};
use crate::PlantError;

/// One number for every joint, or one per joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a number, or a list of numbers with one per joint"
)]
pub enum PerJoint {
    /// The same value for every joint.
    All(f64),
    /// One value per actuated joint, in joint order.
    Each(Vec<f64>),
}

impl Default for PerJoint {
    fn default() -> Self {
        Self::All(0.0)
    }
}

impl PerJoint {
    /// True when every entry is zero (the effect is off).
    pub fn is_zero(&self) -> bool {
        match self {
            Self::All(x) => *x == 0.0,
            Self::Each(v) => v.iter().all(|x| *x == 0.0),
        }
    }

    /// The value per joint for an arm of `n` joints; `key` names it in errors.
    /// Every entry must be finite and not negative.
    pub fn resolve(&self, key: &str, n: usize) -> Result<Vec<f64>, PlantError> {
        self.check(key)?;
        self.resolve_signed(key, n)
    }

    /// As [`PerJoint::resolve`], for a signed quantity (any finite number).
    pub fn resolve_signed(&self, key: &str, n: usize) -> Result<Vec<f64>, PlantError> {
        let v = match self {
            Self::All(x) => vec![*x; n],
            Self::Each(v) if v.len() == n => v.clone(),
            Self::Each(v) => {
                return Err(invalid(
                    key,
                    format!("{} entries", v.len()),
                    format!("one number, or one per actuated joint ({n})"),
                ));
            }
        };
        self.check_signed(key)?;
        Ok(v)
    }

    /// Checks that every entry is finite and not negative, without the arm.
    pub(super) fn check(&self, key: &str) -> Result<(), PlantError> {
        self.check_with(
            key,
            |x| (0.0..=MAX_MAGNITUDE).contains(&x),
            "a number from 0 to 1e9",
        )
    }

    /// Checks that every entry is finite, without the arm.
    pub(super) fn check_signed(&self, key: &str) -> Result<(), PlantError> {
        self.check_with(
            key,
            |x| (-MAX_MAGNITUDE..=MAX_MAGNITUDE).contains(&x),
            "a number from -1e9 to 1e9",
        )
    }

    pub(super) fn check_with(
        &self,
        key: &str,
        ok: fn(f64) -> bool,
        need: &str,
    ) -> Result<(), PlantError> {
        match self {
            Self::All(x) if !ok(*x) => Err(invalid(key, short(*x), need)),
            Self::Each(v) => match v.iter().position(|x| !ok(*x)) {
                Some(i) => Err(invalid(&format!("{key}[{i}]"), short(v[i]), need)),
                None => Ok(()),
            },
            Self::All(_) => Ok(()),
        }
    }
}

/// The largest per-joint setting taken (torques, noise, friction): far past
/// anything physical, far below where sums and squares overflow.
pub const MAX_MAGNITUDE: f64 = 1e9;
