//! The posture an arm's default reference swings about: the middle of each
//! joint's range, unless gravity there asks much of a motor or of a light
//! joint's gain; then, joint by joint, the offset that asks the least.

use plant_rapier::{ArmModel, PlantError};

use crate::probe::Probe;

/// Load over effort at which the middle of the range is good enough.
const COMFORTABLE: f64 = 0.3;
/// Offsets tried, as fractions of the half range from the middle: at most
/// 0.6, since the swing about it takes up to 0.3 more (and the limits
/// must stay out of the reference's way).
const FRACTIONS: [f64; 9] = [0.0, -0.15, 0.15, -0.3, 0.3, -0.45, 0.45, -0.6, 0.6];
/// Passes of coordinate descent over the joints at most.
const PASSES: usize = 4;
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

/// How hard gravity at `q` is on each joint: |G_i| / effort_i or
/// |G_i| M⁻¹_ii / [`HELD_ACCELERATION`], whichever is larger.
fn joint_ratios(model: &ArmModel, q: &[f64]) -> Result<Vec<f64>, PlantError> {
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
        .collect())
}

/// The posture's cost: the worst joint first, then how much the others ask
/// beyond comfortable. A move that unloads a joint other than the worst
/// counts too: the worst one's load often comes from the links beyond it.
fn cost(ratios: &[f64]) -> (f64, f64) {
    let worst = ratios.iter().copied().fold(0.0, f64::max);
    let rest = ratios
        .iter()
        .map(|r| (r - COMFORTABLE).max(0.0).powi(2))
        .sum();
    (worst, rest)
}

/// Whether cost `a` beats `b` by more than rounding.
fn better(a: (f64, f64), b: (f64, f64)) -> bool {
    a.0 < b.0 - 1e-9 || (a.0 <= b.0 + 1e-12 && a.1 < b.1 - 1e-9)
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
    let mut best = cost(&joint_ratios(model, &q)?);
    if best.0 <= COMFORTABLE {
        return Ok(q);
    }
    // Coordinate descent over the joints from the root outwards, until a
    // pass changes nothing.
    for _ in 0..PASSES {
        let mut moved = false;
        for i in 0..q.len() {
            for &x in &options[i] {
                if x == q[i] {
                    continue;
                }
                let mut trial = q.clone();
                trial[i] = x;
                let c = cost(&joint_ratios(model, &trial)?);
                if better(c, best) {
                    best = c;
                    q = trial;
                    moved = true;
                }
            }
        }
        if !moved || best.0 <= COMFORTABLE {
            break;
        }
    }
    Ok(q)
}
