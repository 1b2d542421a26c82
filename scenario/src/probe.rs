//! What the testbed measures of an arm to choose its default gains: M(q)⁻¹
//! and the gravity load G(q), from the plant's response to unit torques at
//! rest. The controller never sees any of it; only the gains it leads to.

use nalgebra::{DMatrix, DVector};
use plant_rapier::{ArmModel, Plant, PlantConfig, PlantError};

/// M(q)⁻¹ and G(q) at one posture, in the controlled joints' coordinates
/// (mimic couplings included, as the controller feels them).
#[derive(Debug, Clone)]
pub struct Probe {
    /// M(q)⁻¹, rad s⁻² per N m.
    pub minv: DMatrix<f64>,
    /// M(q).
    pub m: DMatrix<f64>,
    /// The torque that holds the arm still: G(q), N m.
    pub gravity: DVector<f64>,
}

impl Probe {
    /// Probes `model` at `q` with `armature` (per joint) added.
    pub fn at(model: &ArmModel, q: &[f64], armature: &[f64]) -> Result<Self, PlantError> {
        let n = model.dof();
        // Dry friction would hold a unit torque back: probe without it.
        let config = PlantConfig {
            saturate: false,
            urdf_dynamics: false,
            armature: plant_rapier::PerJoint::Each(armature.to_vec()),
            ..PlantConfig::default()
        };
        let h = 1e-5;
        let accel = |tau: &[f64]| -> Result<Vec<f64>, PlantError> {
            let mut p = Plant::new(model, &config)?;
            p.set_state(q, &vec![0.0; n])?;
            p.step(tau, h)?;
            Ok(p.state().1.iter().map(|v| v / h).collect())
        };
        let a0 = accel(&vec![0.0; n])?;
        let mut minv = DMatrix::zeros(n, n);
        for k in 0..n {
            let mut tau = vec![0.0; n];
            tau[k] = 1.0;
            let a = accel(&tau)?;
            for i in 0..n {
                minv[(i, k)] = a[i] - a0[i];
            }
        }
        let minv = (&minv + minv.transpose()) * 0.5;
        let engine = |what: &str| PlantError::Engine(format!("probing M(q) at {q:?}: {what}"));
        if minv.iter().any(|x| !x.is_finite()) {
            return Err(engine("the response to a unit torque is not finite"));
        }
        let m = minv
            .clone()
            .try_inverse()
            .ok_or_else(|| engine("M(q)⁻¹ is singular"))?;
        // At rest M a0 = −G, so G = −M a0.
        let gravity = -(&m * DVector::from_vec(a0));
        Ok(Self { minv, m, gravity })
    }

    /// Δt · λ_max(K^½ M⁻¹ K^½): below 2 for the discrete loop to be stable (SPEC §11).
    pub fn stability_number(&self, k2: &[f64], dt: f64) -> f64 {
        let s = DVector::from_iterator(k2.len(), k2.iter().map(|k| k.sqrt()));
        let scaled = DMatrix::from_diagonal(&s) * &self.minv * DMatrix::from_diagonal(&s);
        dt * scaled
            .symmetric_eigenvalues()
            .iter()
            .copied()
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ctc`'s matched gains use 1/(M⁻¹)_ii from its Newton–Euler model:
    /// the same as the plant's response to unit torques.
    #[test]
    fn the_laws_effective_inertia_is_the_plants() {
        let model = ArmModel::from_urdf_str(plant_rapier::TWO_LINK_URDF).unwrap();
        let q = [0.3, 1.1];
        let probe = Probe::at(&model, &q, &[0.0, 0.0]).unwrap();
        let mut d = arm_model::dynamics::Dynamics::new(&model, 1.0);
        let m = controller::effective_inertia(&mut d, &q);
        for (i, got) in m.iter().enumerate() {
            let want = 1.0 / probe.minv[(i, i)];
            assert!(
                (got - want).abs() < 1e-3 * want,
                "joint {i}: {got} vs {want}"
            );
        }
    }
}
