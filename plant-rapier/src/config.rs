//! Plant settings, as read from a scenario's `[plant]` table.

use serde::{Deserialize, Serialize};

use crate::PlantError;

/// How the plant integrates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlantConfig {
    /// Rapier steps per control period (default: 8). Rapier's multibody
    /// integrator is first order: 8 keeps a 5 s passive swing within about
    /// 1e-3 rad of an RK4 reference at a 1 ms period.
    pub substeps: u32,
    /// Gravity vector in the URDF's world frame (default: [0, 0, -9.81], m/s²).
    pub gravity: [f64; 3],
    /// Clip each joint's torque to the URDF's effort limit (default: true).
    pub saturate: bool,
}

impl Default for PlantConfig {
    fn default() -> Self {
        Self {
            substeps: 8,
            gravity: [0.0, 0.0, -9.81],
            saturate: true,
        }
    }
}

impl PlantConfig {
    /// Checks every field; the error names the key (`plant.<key>`).
    pub fn validate(&self) -> Result<(), PlantError> {
        if !(1..=1000).contains(&self.substeps) {
            return Err(PlantError::InvalidConfig {
                key: "plant.substeps".into(),
                value: self.substeps.to_string(),
                need: "an integer from 1 to 1000".into(),
            });
        }
        if let Some(g) = self.gravity.iter().find(|g| !g.is_finite()) {
            return Err(PlantError::InvalidConfig {
                key: "plant.gravity".into(),
                value: g.to_string(),
                need: "three finite numbers".into(),
            });
        }
        Ok(())
    }
}
