//! The posture an arm's default reference swings about: the middle of each
//! joint's range, unless gravity there asks much of a motor or of a light
//! joint's gain; then, joint by joint, the offset that asks the least.

use plant_rapier::{ArmModel, PlantError};

use crate::probe::Probe;

/// Load over effort at which the middle of the range is good enough.
const COMFORTABLE: f64 = 0.3;
/// Offsets tried, as fractions of the half range from the middle.
const FRACTIONS: [f64; 5] = [0.0, -0.3, 0.3, -0.6, 0.6];
/// Offsets tried for a joint without limits, rad.
const UNLIMITED: [f64; 4] = [
    0.0,
    -std::f64::consts::FRAC_PI_2,
    std::f64::consts::FRAC_PI_2,
    std::f64::consts::PI,
];

/// The gravity acceleration |G_i| M⁻¹_ii (rad/s²) that the largest gains at
/// 1 kHz hold inside the widest envelope: (ρ/Δt)(K1 Δt/Δt)(0.4 · 0.8 · 0.6 rad).
const HELD_ACCELERATION: f64 = 1000.0 * 200.0 * 0.32 * 0.6;

/// How hard gravity at `q` is on the arm: the largest of |G_i| / effort_i
/// and |G_i| M⁻¹_ii / [`HELD_ACCELERATION`] over the joints.
fn effort_ratio(model: &ArmModel, q: &[f64]) -> Result<f64, PlantError> {
    let p = Probe::at(model, q, &vec![0.0; model.dof()])?;
    Ok(model
        .actuated
        .iter()
        .enumerate()
        .map(|(i, &ji)| {
            let g = p.gravity[i].abs();
            let motor = model.joints[ji].effort.map_or(0.0, |e| g / e);
            motor.max(g * p.minv[(i, i)] / HELD_ACCELERATION)
        })
        .fold(0.0, f64::max))
}

fn candidates(limits: Option<(f64, f64)>) -> Vec<f64> {
    match limits {
        Some((lo, hi)) => FRACTIONS
            .iter()
            .map(|f| 0.5 * (lo + hi) + f * 0.5 * (hi - lo))
            .collect(),
        None => UNLIMITED.to_vec(),
    }
}

/// The reference offsets for `model` (one per controlled joint).
pub(crate) fn choose(model: &ArmModel) -> Result<Vec<f64>, PlantError> {
    let options: Vec<Vec<f64>> = model
        .actuated
        .iter()
        .map(|&ji| candidates(model.joints[ji].limits))
        .collect();
    let mut q: Vec<f64> = options.iter().map(|o| o[0]).collect();
    let mut best = effort_ratio(model, &q)?;
    if best <= COMFORTABLE {
        return Ok(q);
    }
    // Coordinate descent, twice over the joints from the root outwards.
    for _ in 0..2 {
        for i in 0..q.len() {
            for &x in &options[i] {
                if x == q[i] {
                    continue;
                }
                let mut trial = q.clone();
                trial[i] = x;
                let r = effort_ratio(model, &trial)?;
                if r < best - 1e-9 {
                    best = r;
                    q = trial;
                }
            }
        }
    }
    Ok(q)
}
