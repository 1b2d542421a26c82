//! The Rapier plant against the closed form of SPEC §1.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

mod common;

use plant_rapier::{ArmModel, EngineName, Plant, PlantConfig, PlantError, TWO_LINK_URDF};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{FRAC_PI_2, PI};

const DT: f64 = 1e-3;

fn plant(urdf: &str) -> Plant {
    engine_plant(urdf, EngineName::default())
}

fn engine_plant(urdf: &str, engine: EngineName) -> Plant {
    let model = ArmModel::from_urdf_str(urdf).unwrap();
    let config = PlantConfig {
        engine,
        ..PlantConfig::default()
    };
    Plant::new(&model, &config).unwrap()
}

const ENGINES: [EngineName; 2] = [EngineName::Articulated, EngineName::Rapier];

/// The same arm with continuous joints: RK4 knows no hard stops, so a long
/// passive swing is compared on this one.
fn continuous() -> String {
    TWO_LINK_URDF.replace("type=\"revolute\"", "type=\"continuous\"")
}

/// Mean acceleration over one period from (q, q̇) under τ.
fn mean_accel(p: &mut Plant, q: [f64; 2], qd: [f64; 2], tau: [f64; 2]) -> [f64; 2] {
    p.set_state(&q, &qd).unwrap();
    p.step(&tau, DT).unwrap();
    let (_, v) = p.state();
    [(v[0] - qd[0]) / DT, (v[1] - qd[1]) / DT]
}

#[test]
fn joint_order_and_state_round_trip() {
    let mut p = plant(TWO_LINK_URDF);
    assert_eq!(p.joint_names(), ["joint1", "joint2"]);
    assert_eq!(p.dof(), 2);
    p.set_state(&[0.6, 1.8], &[-0.3, 0.4]).unwrap();
    let (q, qd) = p.state();
    assert!((q[0] - 0.6).abs() < 1e-15 && (q[1] - 1.8).abs() < 1e-15);
    assert_eq!(qd, vec![-0.3, 0.4]);
}

/// With q̇ = 0 and τ = G(q) the arm is in static equilibrium: the true
/// acceleration is zero at every instant of the step, so any consistent
/// integrator returns zero up to round-off (measured ~1e-14).
#[test]
fn gravity_torque_holds_the_arm_at_random_states() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut p = plant(&continuous());
    for _ in 0..50 {
        let q = [rng.random_range(-PI..PI), rng.random_range(-PI..PI)];
        let a = mean_accel(&mut p, q, [0.0; 2], common::gravity(q));
        assert!(a[0].abs() < 1e-9 && a[1].abs() < 1e-9, "q = {q:?}: {a:?}");
    }
}

/// τ = G(q) + M(q) e_k at rest must accelerate joint k at exactly 1 rad/s²
/// and the other joint not at all, at the start of the step. Over 1 ms the
/// state moves by 5e-7 rad and 1e-3 rad/s, which changes M, G and C q̇ by
/// parts in 1e-6; the tolerance 1e-5 rad/s² covers that, so a wrong entry
/// of M (or a wrong sign or axis) fails by orders of magnitude.
#[test]
fn mass_matrix_columns_at_random_states() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut p = plant(&continuous());
    for _ in 0..50 {
        let q = [rng.random_range(-PI..PI), rng.random_range(-PI..PI)];
        let (m, g) = (common::mass(q), common::gravity(q));
        for (k, want) in [[1.0, 0.0], [0.0, 1.0]].into_iter().enumerate() {
            let tau = [g[0] + m[0][k], g[1] + m[1][k]];
            let a = mean_accel(&mut p, q, [0.0; 2], tau);
            for i in 0..2 {
                assert!(
                    (a[i] - want[i]).abs() < 1e-5,
                    "q = {q:?}, column {k}: {a:?}"
                );
            }
        }
    }
}

/// At random moving states with random torques, the plant's mean
/// acceleration over one period matches RK4's (the exact mean acceleration
/// of the closed form, to 1e-12). The articulated engine is RK4 itself on
/// its own equations: measured worst error 4e-10 of the largest
/// acceleration with one substep. Rapier's semi-implicit Euler is first
/// order in the substep: 1.5e-3 at its default 6 (1.2e-3 at 8, 2.3e-3 at
/// 4, 7.5e-3 at 1). A missing Coriolis term is of order 1 here (|q̇| up
/// to 4 rad/s), so both bounds catch one.
#[test]
fn one_step_acceleration_at_random_states() {
    for (engine, bound) in [(EngineName::Articulated, 1e-8), (EngineName::Rapier, 2e-3)] {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut p = engine_plant(&continuous(), engine);
        let mut worst: f64 = 0.0;
        for _ in 0..200 {
            let q = [rng.random_range(-PI..PI), rng.random_range(-PI..PI)];
            let qd = [rng.random_range(-4.0..4.0), rng.random_range(-4.0..4.0)];
            let tau = [rng.random_range(-20.0..20.0), rng.random_range(-8.0..8.0)];
            let a = mean_accel(&mut p, q, qd, tau);
            let (_, v) = common::rk4(q, qd, tau, DT, 100);
            let reference = [(v[0] - qd[0]) / DT, (v[1] - qd[1]) / DT];
            let a0 = common::accel(q, qd, tau);
            let scale = a0[0].abs().max(a0[1].abs()).max(1.0);
            for i in 0..2 {
                worst = worst.max((a[i] - reference[i]).abs() / scale);
            }
        }
        assert!(worst < bound, "{engine:?}: worst relative error {worst:e}");
    }
}

/// The default substeps keep a 5 s passive swing near the hanging posture
/// within 1e-4 rad of RK4 (measured 3.9e-5 for Rapier at 6 substeps, its
/// error first order in the substep; 1e-9 for the articulated engine).
#[test]
fn open_loop_swing_near_hanging_tracks_rk4_for_5_s() {
    let q0 = [-FRAC_PI_2 + 0.3, 0.2];
    let (r, _) = common::rk4(q0, [0.0; 2], [0.0; 2], 5.0, 50_000);
    for (engine, bound) in [(EngineName::Articulated, 1e-8), (EngineName::Rapier, 1e-4)] {
        let mut p = engine_plant(&continuous(), engine);
        p.set_state(&q0, &[0.0; 2]).unwrap();
        for _ in 0..5000 {
            p.step(&[0.0; 2], DT).unwrap();
        }
        let (q, _) = p.state();
        assert!(
            (q[0] - r[0]).abs() < bound && (q[1] - r[1]).abs() < bound,
            "{engine:?}: {q:?} vs {r:?}"
        );
    }
}

/// From the paper's initial state the passive arm is chaotic, so errors
/// grow fast; over 0.25 s the measured gap is 5.4e-4 rad for Rapier at 6
/// substeps (4.1e-4 at 8).
#[test]
fn open_loop_from_paper_state_tracks_rk4_briefly() {
    let (r, _) = common::rk4([0.6, 1.8], [0.0; 2], [0.0; 2], 0.25, 2500);
    for (engine, bound) in [(EngineName::Articulated, 1e-8), (EngineName::Rapier, 1e-3)] {
        let mut p = engine_plant(&continuous(), engine);
        p.set_state(&[0.6, 1.8], &[0.0; 2]).unwrap();
        for _ in 0..250 {
            p.step(&[0.0; 2], DT).unwrap();
        }
        let (q, _) = p.state();
        assert!(
            (q[0] - r[0]).abs() < bound && (q[1] - r[1]).abs() < bound,
            "{engine:?}: {q:?} vs {r:?}"
        );
    }
}

/// No hidden joint damping: a passive swing keeps its energy (semi-implicit
/// Euler drifts slowly; Rapier's default damping of 0.1 would drain most of it).
#[test]
fn passive_swing_keeps_its_energy() {
    let mut p = plant(&continuous());
    let q0 = [-FRAC_PI_2 + 0.8, 0.3];
    p.set_state(&q0, &[0.0; 2]).unwrap();
    let e0 = common::energy(q0, [0.0; 2]) - common::energy([-FRAC_PI_2, 0.0], [0.0; 2]);
    for _ in 0..10_000 {
        p.step(&[0.0; 2], DT).unwrap();
    }
    let (q, qd) = p.state();
    let e =
        common::energy([q[0], q[1]], [qd[0], qd[1]]) - common::energy([-FRAC_PI_2, 0.0], [0.0; 2]);
    assert!(
        (e - e0).abs() < 0.02 * e0,
        "swing energy {e0} J became {e} J"
    );
}

#[test]
fn a_hard_stop_holds_the_joint_at_its_limit() {
    // joint2 falls toward -π from a near-folded pose and must not pass the stop.
    let model = ArmModel::from_urdf_str(TWO_LINK_URDF).unwrap();
    let stop = model.joints[1].limits.unwrap().0;
    for engine in ENGINES {
        let mut p = engine_plant(TWO_LINK_URDF, engine);
        p.set_state(&[FRAC_PI_2, -3.0], &[0.0, -3.0]).unwrap();
        let mut lowest = f64::INFINITY;
        for _ in 0..500 {
            p.step(&[0.0, -5.0], DT).unwrap();
            lowest = lowest.min(p.state().0[1]);
        }
        assert!(lowest > stop - 0.02, "{engine:?}: joint2 went to {lowest}");
        // Held there, not bouncing off.
        let (q, qd) = p.state();
        assert!(
            (q[1] - stop).abs() < 0.02 && qd[1].abs() < 0.5,
            "{engine:?}: {q:?} {qd:?}"
        );
    }
}

#[test]
fn bad_torques_are_errors_naming_the_joint() {
    let mut p = plant(TWO_LINK_URDF);
    let err = p.step(&[0.0, f64::NAN], DT).unwrap_err();
    assert_eq!(
        err.to_string(),
        "tau[1] (joint2): NaN is not a finite number"
    );
    assert!(matches!(
        p.step(&[0.0], DT).unwrap_err(),
        PlantError::WrongLength {
            field: "tau",
            expected: 2,
            got: 1
        }
    ));
    assert!(p.set_state(&[f64::INFINITY, 0.0], &[0.0; 2]).is_err());
}
