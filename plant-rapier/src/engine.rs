//! Which engine integrates the arm's rigid-body dynamics (`[plant] engine`).

use serde::{Deserialize, Serialize};

/// The engine that integrates the arm's rigid-body dynamics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EngineName {
    /// The equations of motion in joint coordinates (inertia by the
    /// composite-rigid-body algorithm, bias by Newton–Euler), RK4; dry
    /// friction and hard stops as impulses.
    #[default]
    Articulated,
    /// Rapier's multibody through its whole pipeline (first order).
    Rapier,
}

impl EngineName {
    /// The name a scenario uses.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Articulated => "articulated",
            Self::Rapier => "rapier",
        }
    }
}
