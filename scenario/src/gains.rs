//! Per-joint gains for an arm's default scenario (SPEC §7, §11).
//!
//! K2_i sets how hard joint i's velocity error is pushed back. The discrete
//! loop needs Δt·λ_max(K2^½ M⁻¹ K2^½) < 2; K2_i = ρ / (Δt · max_q M⁻¹_ii)
//! with ρ = 1 (half the limit) equalises that product over the joints, and
//! all K2_i are scaled down together if the coupled λ_max is larger.
//! K1_i then sets the steady error: at steady tracking τ ≈ −K2 K1 Z1, so
//! holding the joint's load τ*_i (gravity, inertia, URDF friction) within
//! 40 % of the envelope needs K1_i ≥ τ*_i / (0.4 k_c,i K2_i). K1_i is kept
//! at most 0.2/Δt so that the position loop stays well inside the velocity
//! loop; where that is not enough the joint's envelope is widened, as far
//! as its range allows. Where that is not enough either, the joint is
//! reported (`armature`): armature raises M_ii, hence K2, at the same rate.
//! K1_i is at least the paper's 15, or less where a weak motor cannot
//! follow 15 from the start's error and the load needs less
//! (`motor_bound.rs`).
//!
//! The barrier term γ Z1γ/(β D) of the law (SPEC §7) is a position gain of
//! its own, K_b = γ²(k_c² + Z1γ²)/(β (k_c² − Z1γ²)²), which K1 and K2 do
//! not scale. The sampled loop of a joint with velocity gain K2 and total
//! position gain K1 K2 + K_b is stable while K1 Δt + K_b Δt/K2 < 2 (Jury's
//! test on the double integrator with a zero-order hold; M⁻¹ cancels). On a
//! feather-light joint K2 is tiny, so K_b alone can break it: the envelope
//! is widened until K_b Δt/K2 ≤ 1 out to |Z1γ| = 0.8 k_c, and where its range
//! does not allow that, the joint is reported (`armature`) for the default
//! scenario to add armature or lock it. The shifting term a γ̇² … of α adds
//! K2-scaled stiffness of order a (3/T_c)²/β, under 1e-2 of the budget.

use plant_rapier::{ArmModel, PlantError};

use crate::Scenario;
use crate::motor_bound::{K1Floor, MotorBound};
use crate::probe::{Probe, Prober};

/// Target for Δt·λ_max(K2^½ M⁻¹ K2^½): half the stability limit.
const RHO: f64 = 1.0;
/// Steady error aimed for, as a fraction of the smallest k_c.
const ERROR_FRACTION: f64 = 0.4;
/// K1_i Δt at most.
const K1_DT_MAX: f64 = 0.2;
/// The paper's gain: the smallest K1_i chosen.
const K1_MIN: f64 = 15.0;
/// Reference time between two postures probed, s: M(q) changes little
/// between them, and the postures halfway are checked too.
const PROBE_SPACING_S: f64 = 0.05;
/// Postures probed on the straight way from q(0) to the reference's start
/// (the arm crosses them before T_c).
const APPROACH: usize = 4;
/// How far into the envelope the loop must stay stable with the barrier
/// term: |Z1γ| up to this fraction of k_c (the steady error aimed for is 0.4).
const BARRIER_EDGE: f64 = 0.8;
/// The barrier's share of the sampled loop's stability budget of 2
/// (K1 Δt ≤ 0.2 takes another share).
const BARRIER_BUDGET: f64 = 1.0;
/// Armature added beyond the bare need, for the coupling and the postures
/// between those probed.
const ARMATURE_MARGIN: f64 = 1.25;

/// (k_c² + x²)/(k_c² − x²)² · k_c² at x = [`BARRIER_EDGE`] k_c: the barrier's
/// stiffness there is this over β k_c² (γ = 1).
fn barrier_factor() -> f64 {
    let f2 = BARRIER_EDGE * BARRIER_EDGE;
    (1.0 + f2) / ((1.0 - f2) * (1.0 - f2))
}

/// One joint's gains and the numbers they come from.
#[derive(Debug, Clone)]
pub struct JointGain {
    /// Joint name.
    pub name: String,
    /// K1_i, 1/s.
    pub k1: f64,
    /// K2_i, N m s/rad.
    pub k2: f64,
    /// The largest M⁻¹_ii over the postures probed.
    pub minv_diag: f64,
    /// τ*_i: the largest torque the reference needs, N m.
    pub load: f64,
    /// The largest gravity torque |G_i| along the reference, N m.
    pub gravity: f64,
    /// Its effort limit, if any.
    pub effort: Option<f64>,
    /// Why K1_i is what it is.
    pub k1_reason: String,
    /// The least time in which the joint's motor, with what its load
    /// leaves of its effort, brings it from its start into its envelope, s
    /// (`motor_bound.rs`); none without an effort limit or with no
    /// room beyond the load.
    pub motor_entry_s: Option<f64>,
    /// The barrier term's share of the sampled loop's stability budget,
    /// K_b Δt/K2_i at |Z1γ| = 0.8 k_c of the chosen envelope (≤ 1 is held).
    pub barrier: f64,
    /// Why the envelope was widened, if it was.
    pub envelope_reason: Option<String>,
    /// Armature (kg m² or kg) the joint needs for the barrier term to be
    /// held at this rate, when widening its envelope is not enough.
    pub armature_needed: Option<f64>,
    /// What the armature is for.
    pub armature_for: Option<ArmatureFor>,
}

/// Why a joint needs armature at the scenario's rate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArmatureFor {
    /// The barrier term's stiffness breaks the sampled loop of a light joint.
    Barrier,
    /// No K1 ≤ 0.2/Δt holds the load within 40 % of the widest envelope.
    Load,
}

/// The gains of every joint, the rate, and the margins behind them.
#[derive(Debug, Clone)]
pub struct GainChoice {
    /// Control rate, Hz.
    pub rate_hz: f64,
    /// Per joint.
    pub joints: Vec<JointGain>,
    /// The largest Δt·λ_max(K2^½ M⁻¹ K2^½) over the postures checked
    /// (< 2 is stable; the gains aim for 1).
    pub stability_number: f64,
    /// How many postures along the reference (and on the way to it) the
    /// stability number was checked at.
    pub postures_checked: usize,
    /// Envelope offset k_c per joint: the scenario's, or wider where the
    /// load needs it and the joint's range allows it.
    pub envelope: Vec<f64>,
}

impl GainChoice {
    /// Joints no gain holds at this rate (see [`JointGain::armature_needed`]).
    pub fn unheld(&self) -> Vec<usize> {
        (0..self.joints.len())
            .filter(|&i| self.joints[i].armature_needed.is_some())
            .collect()
    }

    /// Joints whose K2_i is below the analysis's ½ (allowed, SPEC §7).
    pub fn below_half(&self) -> Vec<&str> {
        self.joints
            .iter()
            .filter(|j| j.k2 <= 0.5)
            .map(|j| j.name.as_str())
            .collect()
    }
}

/// The reference's posture at `t`.
fn reference_at(s: &Scenario, t: f64) -> Vec<f64> {
    s.reference.joints.iter().map(|r| r.eval(t)[0]).collect()
}

/// The postures probed: the reference every [`PROBE_SPACING_S`] (and at
/// its end), q(0), and the way from q(0) to the reference's start.
fn postures(s: &Scenario) -> Vec<Vec<f64>> {
    let count = (s.duration_s / PROBE_SPACING_S).ceil().max(1.0) as usize;
    let mut out: Vec<Vec<f64>> = (0..=count)
        .map(|k| reference_at(s, s.duration_s * k as f64 / count as f64))
        .collect();
    let (q0, start) = (&s.initial.q, reference_at(s, 0.0));
    for k in 0..APPROACH {
        let f = k as f64 / APPROACH as f64;
        out.push(
            q0.iter()
                .zip(&start)
                .map(|(a, b)| a + f * (b - a))
                .collect(),
        );
    }
    out
}

/// The postures halfway between those [`postures`] takes on the reference:
/// where the loop's stability is checked again.
fn midpoints(s: &Scenario) -> Vec<Vec<f64>> {
    let count = (s.duration_s / PROBE_SPACING_S).ceil().max(1.0) as usize;
    (0..count)
        .map(|k| reference_at(s, s.duration_s * (k as f64 + 0.5) / count as f64))
        .collect()
}

/// What the plant reports about the arm along the reference.
struct Measured {
    probes: Vec<Probe>,
    /// Probes halfway between the reference's: for the stability check.
    between: Vec<Probe>,
    minv_diag: Vec<f64>,
    /// The smallest M⁻¹_ii over the postures probed: how little a joint's
    /// own torque may accelerate it.
    minv_diag_low: Vec<f64>,
    load: Vec<f64>,
    gravity: Vec<f64>,
}

/// Probes the arm at the reference's postures; the load τ*_i of each joint.
fn measure(model: &ArmModel, s: &Scenario) -> Result<Measured, PlantError> {
    let n = model.dof();
    let armature = s.plant.armature_for(model)?;
    let mut prober = Prober::new(model, &armature)?;
    let probes = postures(s)
        .iter()
        .map(|q| prober.at(q))
        .collect::<Result<Vec<_>, _>>()?;
    let between = midpoints(s)
        .iter()
        .map(|q| prober.at(q))
        .collect::<Result<Vec<_>, _>>()?;
    let minv_diag: Vec<f64> = (0..n)
        .map(|i| probes.iter().map(|p| p.minv[(i, i)]).fold(0.0, f64::max))
        .collect();
    let minv_diag_low: Vec<f64> = (0..n)
        .map(|i| {
            probes
                .iter()
                .map(|p| p.minv[(i, i)])
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    let r = &s.reference.joints;
    let qdd_max: Vec<f64> = r.iter().map(trajectory::Signal::accel_bound).collect();
    let load: Vec<f64> = (0..n)
        .map(|i| {
            let j = &model.joints[model.actuated[i]];
            let inertial = |p: &Probe| (0..n).map(|k| p.m[(i, k)].abs() * qdd_max[k]).sum::<f64>();
            let worst = probes
                .iter()
                .map(|p| p.gravity[i].abs() + inertial(p))
                .fold(0.0, f64::max);
            let qd_max = r[i].speed_bound();
            let urdf = if s.plant.urdf_dynamics {
                j.friction + j.damping * qd_max
            } else {
                0.0
            };
            worst + urdf
        })
        .collect();
    let gravity = (0..n)
        .map(|i| {
            probes
                .iter()
                .map(|p| p.gravity[i].abs())
                .fold(0.0, f64::max)
        })
        .collect();
    Ok(Measured {
        probes,
        between,
        minv_diag,
        minv_diag_low,
        load,
        gravity,
    })
}

impl Measured {
    /// The largest stability number of `k2` over every posture probed and
    /// every one halfway between them.
    fn stability_number(&self, k2: &[f64], dt: f64) -> f64 {
        self.probes
            .iter()
            .chain(&self.between)
            .map(|p| p.stability_number(k2, dt))
            .fold(0.0, f64::max)
    }
}

/// K2 at period `dt`: ρ/(Δt M⁻¹_ii), scaled down together to the coupled
/// bound at every posture checked.
fn k2_at(m: &Measured, dt: f64) -> Vec<f64> {
    let mut k2: Vec<f64> = m.minv_diag.iter().map(|x| RHO / (dt * x)).collect();
    let worst = m.stability_number(&k2, dt);
    if worst > RHO {
        k2.iter_mut().for_each(|k| *k *= RHO / worst);
    }
    k2
}

/// The gains for `model` running `s` (reference, envelope, plant settings);
/// `kc_cap` is the widest envelope offset each joint may be given.
pub fn choose_gains(
    model: &ArmModel,
    s: &Scenario,
    kc_cap: &[f64],
) -> Result<GainChoice, PlantError> {
    let n = model.dof();
    let m = measure(model, s)?;
    let kc: Vec<f64> = s.envelope.joints.iter().map(|e| e.offset).collect();
    // The envelope's smallest value over its offset (0.8 for the default's ±20 %).
    let kc_low: Vec<f64> = s
        .envelope
        .joints
        .iter()
        .map(|e| e.min_value() / e.offset)
        .collect();
    let beta = s.controller.beta;
    let rate = s.rate_hz;
    let dt = 1.0 / rate;
    let k2 = k2_at(&m, dt);
    let k1_max = K1_DT_MAX / dt;
    let need: Vec<f64> = (0..n)
        .map(|i| m.load[i] / (ERROR_FRACTION * kc_low[i] * kc[i] * k2[i]))
        .collect();
    // The envelope the barrier term needs: K_b Δt/K2 ≤ the budget.
    let barrier_kc: Vec<f64> = (0..n)
        .map(|i| (barrier_factor() * dt / (beta * k2[i] * BARRIER_BUDGET)).sqrt() / kc_low[i])
        .collect();
    // Where K1 is capped, the envelope may widen up to its cap instead.
    let load_kc: Vec<f64> = (0..n)
        .map(|i| kc[i] * (need[i] / k1_max).max(1.0))
        .collect();
    let cap: Vec<f64> = (0..n).map(|i| kc_cap[i].max(kc[i])).collect();
    let envelope: Vec<f64> = (0..n)
        .map(|i| load_kc[i].max(barrier_kc[i]).min(cap[i]))
        .collect();
    let start = reference_at(s, 0.0);
    let motor: Vec<Option<MotorBound>> = (0..n)
        .map(|i| {
            let effort = model.joints[model.actuated[i]].effort;
            let start_error = (s.initial.q[i] - start[i]).abs();
            MotorBound::new(effort, m.load[i], m.minv_diag_low[i], start_error, kc[i])
        })
        .collect();
    let floor: Vec<K1Floor> = (0..n)
        .map(|i| K1Floor::at(K1_MIN.min(k1_max), motor[i], envelope[i]))
        .collect();
    let mut joints = joint_gains(model, &m, &k2, &need, &floor, k1_max);
    for (i, j) in joints.iter_mut().enumerate() {
        j.motor_entry_s = motor[i].map(|b| b.entry_time(envelope[i], kc_low[i]));
        let low = kc_low[i] * envelope[i];
        j.barrier = barrier_factor() * dt / (beta * low * low * k2[i]);
        j.envelope_reason = (envelope[i] > kc[i] * (1.0 + 1e-9)).then(|| {
            if barrier_kc[i] > load_kc[i] {
                "the barrier term on a light joint (K_b Δt/K2 ≤ 1)".to_string()
            } else {
                format!("the load, with K1 capped at {k1_max:.0}")
            }
        });
        // M⁻¹_ii with armature a is M⁻¹_ii/(1 + a M⁻¹_ii) (Sherman–Morrison),
        // and K2 = ρ_i/(Δt M⁻¹_ii) grows with it.
        let minv = m.minv_diag[i];
        let rho = k2[i] * dt * minv;
        if j.barrier > BARRIER_BUDGET * (1.0 + 1e-9) {
            let target = BARRIER_BUDGET * beta * low * low * rho / (barrier_factor() * dt * dt);
            j.armature_needed = Some(round2(ARMATURE_MARGIN * (1.0 / target - 1.0 / minv)));
            j.armature_for = Some(ArmatureFor::Barrier);
        } else if load_kc[i] > cap[i] * (1.0 + 1e-9) {
            // K1_max K2 must hold the load within 40 % of the widest
            // envelope: K2 ≥ load/c. The armature adds a q̈_d,i to the load.
            let c = ERROR_FRACTION * kc_low[i] * cap[i] * k1_max;
            let qdd = s
                .reference
                .joints
                .get(i)
                .map_or(0.0, trajectory::Signal::accel_bound);
            let per_armature = rho / dt - qdd / c;
            let a = (m.load[i] / c - rho / (dt * minv)) / per_armature;
            if per_armature > 0.0 && a > 0.0 {
                j.armature_needed = Some(round2(ARMATURE_MARGIN * a));
                j.armature_for = Some(ArmatureFor::Load);
            }
        }
    }
    Ok(GainChoice {
        rate_hz: rate,
        joints,
        stability_number: m.stability_number(&k2, dt),
        postures_checked: m.probes.len() + m.between.len(),
        envelope,
    })
}

fn joint_gains(
    model: &ArmModel,
    m: &Measured,
    k2: &[f64],
    need: &[f64],
    floor: &[K1Floor],
    k1_max: f64,
) -> Vec<JointGain> {
    (0..k2.len())
        .map(|i| JointGain {
            name: model.joints[model.actuated[i]].name.clone(),
            k1: need[i].clamp(floor[i].k1, k1_max),
            k2: k2[i],
            minv_diag: m.minv_diag[i],
            load: m.load[i],
            gravity: m.gravity[i],
            effort: model.joints[model.actuated[i]].effort,
            k1_reason: k1_reason(need[i], &floor[i], k1_max),
            motor_entry_s: None,
            barrier: 0.0,
            envelope_reason: None,
            armature_needed: None,
            armature_for: None,
        })
        .collect()
}

/// `x` rounded up to two significant digits (a value users read and copy).
fn round2(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let scale = 10f64.powf(x.log10().floor() - 1.0);
    (x / scale).ceil() * scale
}

fn k1_reason(need: f64, floor: &K1Floor, k1_max: f64) -> String {
    match floor.motor {
        Some(b) if need <= floor.k1 => format!(
            "√(a/E) = {:.2}, under the paper's {K1_MIN}: its motor turns it at {:.3} rad/s² beyond its load, and a higher K1 overshoots from its start {:.3} rad away (the load needs {need:.2})",
            floor.k1,
            b.accel,
            b.start_error(floor.envelope)
        ),
        Some(_) if need <= K1_MIN => format!(
            "holds the load within 40 % of the envelope (needs {need:.2}; its motor's √(a/E) = {:.2} is lower, and the load comes first)",
            floor.k1
        ),
        _ if need <= K1_MIN => {
            format!("the paper's {K1_MIN} already holds the load (needs {need:.2})")
        }
        _ if need <= k1_max => "holds the load within 40 % of the envelope".into(),
        _ => format!(
            "capped at 0.2/Δt = {k1_max:.0} (the load needs {need:.0}): the envelope is widened"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps ẍ = M⁻¹ u, u = −K_d ẋ − K_p x held over each period (exact
    /// for a constant u), and says whether it grew a thousandfold.
    fn grows(kp: f64, kd: f64, minv: f64, dt: f64) -> bool {
        let (mut x, mut v) = (1e-3, 0.0);
        for _ in 0..5000 {
            let a = minv * (-kd * v - kp * x);
            x += v * dt + 0.5 * a * dt * dt;
            v += a * dt;
            if x.is_nan() || x.abs() >= 1.0 {
                return true;
            }
        }
        false
    }

    /// The bound the barrier budget rests on: with K2 = 1/(Δt M⁻¹) the
    /// sampled loop holds while (K1 K2 + K_b) Δt < 2 K2, whatever M⁻¹ (a
    /// feather-light 1e6 as well as a shoulder's 1).
    #[test]
    fn the_sampled_loop_holds_below_twice_the_velocity_gain() {
        let dt = 1e-3;
        for minv in [1.0, 1e3, 1e6] {
            let kd = 1.0 / (dt * minv);
            for share in [0.2, 1.0, 1.9] {
                assert!(
                    !grows(share * kd / dt, kd, minv, dt),
                    "M⁻¹ {minv}, share {share}"
                );
            }
            for share in [2.1, 3.0] {
                assert!(
                    grows(share * kd / dt, kd, minv, dt),
                    "M⁻¹ {minv}, share {share}"
                );
            }
        }
        // The barrier's stiffness grows fast near the edge: 12.6/(β k_c²)
        // at 0.8 k_c, 1/(β k_c²) at the centre.
        assert!((barrier_factor() - 1.64 / 0.1296).abs() < 1e-12);
    }

    #[test]
    fn armature_amounts_round_up_to_two_digits() {
        assert!((round2(4.2345e-6) - 4.3e-6).abs() < 1e-18);
        assert_eq!(round2(0.0), 0.0);
    }
}
