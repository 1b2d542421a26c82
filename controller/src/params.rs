//! Controller parameters (SPEC §11), as read from a scenario's `[controller]` table.

use serde::{Deserialize, Serialize};

use crate::{ControllerError, Gain};

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

/// Every parameter of the law. Unset keys take the paper's values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ControllerParams {
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
}

impl Default for ControllerParams {
    fn default() -> Self {
        Self {
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
            a: 1.0,
            psi: 1.0,
            k_a: 0.1,
            q_weight: 1.0,
            r_weight: 0.01,
            integrator: Integrator::Exact,
            barrier: BarrierMode::PerJoint,
            breach_epsilon: 1e-6,
        }
    }
}

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
        if self.neurons == 0 {
            return Err(ControllerError::InvalidParameter {
                key: "controller.neurons".into(),
                value: "0".into(),
                need: "at least 1".into(),
            });
        }
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
        let p = ControllerParams {
            neurons: 0,
            ..Default::default()
        };
        assert!(
            p.validate()
                .unwrap_err()
                .to_string()
                .contains("controller.neurons")
        );
    }
}
