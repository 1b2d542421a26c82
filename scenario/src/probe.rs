//! What the testbed measures of an arm to choose its default gains: M(q),
//! M(q)⁻¹ and the gravity load G(q), from the plant's own joint-space
//! dynamics at rest. The controller never sees any of it; only the gains
//! it leads to.

use nalgebra::{DMatrix, DVector};
use plant_rapier::{ArmModel, EngineError, EngineName, Plant, PlantConfig, PlantError};

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

/// One plant probed at many postures (building it once).
#[derive(Debug)]
pub struct Prober {
    plant: Plant,
    rest: Vec<f64>,
}

impl Prober {
    /// The plant of `model` with `armature` (per joint) added, to probe,
    /// under the default gravity (what the gains are chosen for).
    pub fn new(model: &ArmModel, armature: &[f64]) -> Result<Self, PlantError> {
        Self::with_gravity(model, armature, PlantConfig::default().gravity)
    }

    /// [`Prober::new`] under `gravity` (m/s², world frame): a run's own
    /// loads, e.g. none in a scenario with `plant.gravity` zero.
    pub fn with_gravity(
        model: &ArmModel,
        armature: &[f64],
        gravity: [f64; 3],
    ) -> Result<Self, PlantError> {
        let config = PlantConfig {
            engine: EngineName::Articulated,
            saturate: false,
            urdf_dynamics: false,
            armature: plant_rapier::PerJoint::Each(armature.to_vec()),
            gravity,
            ..PlantConfig::default()
        };
        Ok(Self {
            plant: Plant::new(model, &config)?,
            rest: vec![0.0; model.dof()],
        })
    }

    /// M(q)⁻¹, M(q) and G(q) at `q`.
    ///
    /// M and G are read from the articulated engine, not differenced from
    /// a short step's response to unit torques: on a near-singular arm
    /// (a head whose inertia is a point mass on its axis, M⁻¹_ii ~ 1e8)
    /// the step itself moves the joint fast enough that its response is
    /// no longer linear, and the load G = −M a₀ came out wrong by orders.
    pub fn at(&mut self, q: &[f64]) -> Result<Probe, PlantError> {
        let n = self.rest.len();
        self.plant.set_state(q, &self.rest)?;
        let (m, bias) = self.plant.inertia_and_bias()?;
        let engine = |what: &'static str| {
            PlantError::from(EngineError::Probe {
                q: q.to_vec(),
                what,
            })
        };
        let m = DMatrix::from_row_slice(n, n, &m);
        let m = (&m + m.transpose()) * 0.5;
        let minv = m
            .clone()
            .cholesky()
            .map(|c| c.inverse())
            .ok_or_else(|| engine("is not positive definite"))?;
        if minv.iter().any(|x| !x.is_finite()) {
            return Err(engine("has an inverse that is not finite"));
        }
        // At rest the bias is G(q) alone.
        let gravity = DVector::from_vec(bias);
        Ok(Probe { minv, m, gravity })
    }
}

impl Probe {
    /// Probes `model` at `q` with `armature` (per joint) added (see
    /// [`Prober::at`]).
    pub fn at(model: &ArmModel, q: &[f64], armature: &[f64]) -> Result<Self, PlantError> {
        Prober::new(model, armature)?.at(q)
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
    /// the same as the plant's M(q)⁻¹.
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
