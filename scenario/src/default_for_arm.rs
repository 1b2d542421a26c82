//! A scenario that works on any arm: what `--robot PATH` runs when no
//! scenario file is given.
//!
//! Per joint, a smooth sinusoid about the middle of its range; an envelope
//! of about 0.25 rad; an initial state outside the envelope, so the
//! deferred constraint is exercised; and gains scaled to the arm. The
//! paper's gains suit the paper's arm only: the discrete loop needs
//! Δt·K2·λ_max(M⁻¹) < 2 (SPEC §11), so K2 is chosen from the arm's inertia,
//! measured by probing the plant (the controller itself still gets no model).

use plant_rapier::{ArmModel, JointKind, Plant, PlantConfig, PlantError};
use trajectory::{EnvelopeConfig, ReferenceConfig, Sinusoid};

use crate::{Initial, Scenario};

/// Largest gain the paper uses.
const PAPER_GAIN: f64 = 15.0;
/// Δt·K2·λ_max(M⁻¹) aimed for: half the stability limit, since M
/// changes with the posture.
const MARGIN: f64 = 1.0;
/// Smallest K2 worth running; below it the rate is raised.
const MIN_GAIN: f64 = 5.0;
const MAX_RATE_HZ: f64 = 10_000.0;

/// The largest eigenvalue of M(q)⁻¹ at `q` (rad⁻¹ s⁻² per N m), from the
/// plant's response to unit joint torques at rest.
pub fn max_inverse_inertia(model: &ArmModel, q: &[f64]) -> Result<f64, PlantError> {
    let n = model.dof();
    let config = PlantConfig {
        saturate: false,
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
    let mut minv = nalgebra::DMatrix::zeros(n, n);
    for k in 0..n {
        let mut tau = vec![0.0; n];
        tau[k] = 1.0;
        let a = accel(&tau)?;
        for i in 0..n {
            minv[(i, k)] = a[i] - a0[i];
        }
    }
    let sym = (&minv + minv.transpose()) * 0.5;
    Ok(sym
        .symmetric_eigenvalues()
        .iter()
        .copied()
        .fold(0.0, f64::max))
}

impl Scenario {
    /// The default scenario for `model` (see the module docs).
    pub fn for_arm(model: &ArmModel) -> Result<Self, PlantError> {
        let mut reference = Vec::new();
        let mut envelope = Vec::new();
        for (i, &ji) in model.actuated.iter().enumerate() {
            let j = &model.joints[ji];
            let (center, half) = match j.limits {
                Some((lo, hi)) => (0.5 * (lo + hi), 0.5 * (hi - lo)),
                None => (0.0, f64::INFINITY),
            };
            let (amp, kc) = match j.kind {
                JointKind::Prismatic => (0.3 * half, 0.15 * half),
                _ => ((0.3 * half).min(0.5), 0.25f64.min(0.3 * half)),
            };
            let omega = 0.8 + 0.2 * (i % 3) as f64;
            // Alternate sin and cos so the joints do not all start at rest.
            reference.push(if i % 2 == 0 {
                Sinusoid {
                    offset: center,
                    sin: amp,
                    cos: 0.0,
                    omega,
                }
            } else {
                Sinusoid {
                    offset: center,
                    sin: 0.0,
                    cos: amp,
                    omega,
                }
            });
            envelope.push(Sinusoid {
                offset: kc,
                sin: 0.2 * kc,
                cos: 0.0,
                omega: 0.5,
            });
        }
        let mut s = Scenario {
            name: format!("default for {}", model.name),
            duration_s: 10.0,
            reference: ReferenceConfig {
                joints: reference,
                rate_hz: None,
            },
            envelope: EnvelopeConfig {
                joints: envelope,
                from_limits: false,
            },
            ..Scenario::default()
        };
        // Start 1.5 envelopes away from the reference: outside the bound,
        // inside the joint limits.
        let mut q0 = Vec::new();
        for (i, &ji) in model.actuated.iter().enumerate() {
            let [qd0, _, _] = s.reference.joints[i].eval(0.0);
            let [kc0, _, _] = s.envelope.joints[i].eval(0.0);
            let mut q = qd0 + 1.5 * kc0;
            if let Some((lo, hi)) = model.joints[ji].limits {
                let pad = 0.02 * (hi - lo);
                q = q.clamp(lo + pad, hi - pad);
            }
            q0.push(q);
        }
        let n = q0.len();
        s.initial = Initial {
            q: q0,
            qd: vec![0.0; n],
        };

        let lambda = max_inverse_inertia(model, &s.initial.q)?;
        let mut rate = s.rate_hz;
        let mut gain = PAPER_GAIN.min(MARGIN * rate / lambda.max(1e-9));
        if gain < MIN_GAIN {
            // A multiple of 100 Hz keeps the period a round number of ns.
            rate = ((MIN_GAIN * lambda / MARGIN / 100.0).ceil() * 100.0).min(MAX_RATE_HZ);
            gain = PAPER_GAIN.min(MARGIN * rate / lambda).max(0.6);
        }
        s.rate_hz = rate;
        s.controller.k1 = gain.max(1.01);
        s.controller.k2 = gain;
        Ok(s)
    }
}
