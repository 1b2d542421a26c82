//! Each effect of a scenario's `[plant]` changes the arm as it should,
//! checked against the closed form of SPEC §1 where there is one.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

mod common;

use plant_rapier::{ArmModel, Effects, PayloadConfig, PerJoint, PlantConfig, Rig, TWO_LINK_URDF};

const PERIOD_NS: u64 = 1_000_000;
const DT: f64 = 1e-3;

/// Continuous joints: no hard stop can interfere with a measurement.
fn model() -> ArmModel {
    ArmModel::from_urdf_str(&TWO_LINK_URDF.replace("type=\"revolute\"", "type=\"continuous\""))
        .unwrap()
}

fn rig(config: &PlantConfig, seed: u64) -> Rig {
    Rig::new(&model(), config, seed, PERIOD_NS).unwrap()
}

fn config(f: impl FnOnce(&mut PlantConfig)) -> PlantConfig {
    let mut c = PlantConfig::default();
    f(&mut c);
    c
}

fn state(r: &Rig) -> ([f64; 2], [f64; 2]) {
    let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
    r.true_state_into(&mut q, &mut qd);
    (q, qd)
}

/// Mean acceleration over one period from (q, q̇) under the command τ.
fn mean_accel(r: &mut Rig, q: [f64; 2], qd: [f64; 2], tau: [f64; 2]) -> [f64; 2] {
    r.set_state(&q, &qd).unwrap();
    r.step(Some(&tau)).unwrap();
    let (_, v) = state(r);
    [(v[0] - qd[0]) / DT, (v[1] - qd[1]) / DT]
}

fn m_times(q: [f64; 2], a: [f64; 2]) -> [f64; 2] {
    let m = common::mass(q);
    [
        m[0][0] * a[0] + m[0][1] * a[1],
        m[1][0] * a[0] + m[1][1] * a[1],
    ]
}

/// With friction on, the same state and command lose M Δa = b q̇ + F_c
/// tanh(q̇/v_s) per joint, opposite to q̇. Over 1 ms q̇ changes by about 1 %
/// (the friction itself decelerates the joint), so 2 % is the bound; a
/// wrong sign or a missing term is off by 100 % or more.
#[test]
fn friction_opposes_motion_with_the_set_magnitude() {
    let (b, fc) = ([0.8, 0.3], [1.5, 0.6]);
    let with = config(|c| {
        c.friction.viscous = PerJoint::Each(b.to_vec());
        c.friction.coulomb = PerJoint::Each(fc.to_vec());
    });
    let q = [0.3, -0.7];
    for qd in [[1.2, -0.9], [-2.0, 0.5]] {
        let tau = common::gravity(q);
        let a0 = mean_accel(&mut rig(&PlantConfig::default(), 0), q, qd, tau);
        let mut r = rig(&with, 0);
        let a1 = mean_accel(&mut r, q, qd, tau);
        let lost = m_times(q, [a1[0] - a0[0], a1[1] - a0[1]]);
        for i in 0..2 {
            let want = -(b[i] * qd[i] + fc[i] * (qd[i] / 0.01).tanh());
            assert!(want.signum() == -qd[i].signum());
            assert!(
                (lost[i] - want).abs() < 0.02 * want.abs(),
                "joint {i}, q̇ = {qd:?}: {lost:?} vs {want}"
            );
        }
        assert!(r.effects().has(Effects::FRICTION));
    }
    // At rest Coulomb friction vanishes smoothly (no stick-slip jump).
    let r = rig(&with, 0);
    assert_eq!(r.plant().friction_torque(), [0.0, 0.0]);
}

/// A point mass m at the tip of link 2 adds m g (l1 cos q1 + l2 cos(q1+q2))
/// and m g l2 cos(q1+q2) to the gravity torques: the arm holds still under
/// τ = G(q) + that, and only once the payload is attached.
#[test]
fn a_payload_changes_the_gravity_torque_by_the_expected_amount() {
    let (m, l2) = (1.5, 0.31);
    let c = config(|c| {
        c.payload = Some(PayloadConfig {
            link: "link2".into(),
            mass: m,
            offset: [l2, 0.0, 0.0],
            attach_at_s: 0.005,
        });
    });
    let q = [0.4, 0.9];
    let g = common::gravity(q);
    let extra = [
        m * common::G * (common::L1 * q[0].cos() + l2 * (q[0] + q[1]).cos()),
        m * common::G * l2 * (q[0] + q[1]).cos(),
    ];
    let mut r = rig(&c, 0);
    // Before 5 ms the arm carries nothing: G(q) holds it.
    for _ in 0..5 {
        let a = mean_accel(&mut r, q, [0.0; 2], g);
        assert!(a[0].abs() < 1e-9 && a[1].abs() < 1e-9, "{a:?}");
        assert!(!r.effects().has(Effects::PAYLOAD));
    }
    assert!(r.payload_attached());
    let held = [g[0] + extra[0], g[1] + extra[1]];
    let a = mean_accel(&mut r, q, [0.0; 2], held);
    assert!(a[0].abs() < 1e-9 && a[1].abs() < 1e-9, "{a:?}");
    assert!(r.effects().has(Effects::PAYLOAD));
    // Without the extra torque the loaded arm falls (the shoulder drops;
    // the elbow, relative to it, swings the other way).
    let a = mean_accel(&mut r, q, [0.0; 2], g);
    assert!(a[0] < -1.0, "{a:?}");
}

/// The tool link of the three-link arm is merged into link 3 by a fixed
/// joint; a payload named by it sits where the tool frame is.
#[test]
fn a_payload_on_a_merged_link_sits_in_that_links_frame() {
    let urdf = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../robots/three_link_planar.urdf"
    ))
    .unwrap();
    let model = ArmModel::from_urdf_str(&urdf).unwrap();
    let (into, frame) = model.locate_link("tool").unwrap();
    assert_eq!(model.links[into].name, "link3");
    let on = |link: &str, offset: [f64; 3]| {
        let c = config(|c| {
            c.payload = Some(PayloadConfig {
                link: link.into(),
                mass: 2.0,
                offset,
                attach_at_s: 0.0,
            });
        });
        let mut r = Rig::new(&model, &c, 0, PERIOD_NS).unwrap();
        r.set_state(&[0.2, 0.3, 0.4], &[0.0; 3]).unwrap();
        r.step(Some(&[0.0; 3])).unwrap();
        let (mut q, mut qd) = ([0.0; 3], [0.0; 3]);
        r.true_state_into(&mut q, &mut qd);
        qd
    };
    let a = on("tool", [0.0; 3]);
    let b = on("link3", frame.xyz);
    for i in 0..3 {
        assert!((a[i] - b[i]).abs() < 1e-12, "{a:?} vs {b:?}");
    }
}

/// With no gravity and the arm at rest, nothing happens until the first
/// command arrives: a delay of N periods gives the undelayed response N
/// steps later, to the bit.
#[test]
fn a_delay_of_n_periods_shifts_the_response_by_n_steps() {
    let n = 3;
    let base = config(|c| c.gravity = [0.0; 3]);
    let delayed = config(|c| {
        c.gravity = [0.0; 3];
        c.actuation.delay_periods = n as u32;
    });
    let run = |c: &PlantConfig| {
        let mut r = rig(c, 0);
        r.set_state(&[0.5, -0.5], &[0.0; 2]).unwrap();
        (0..40)
            .map(|k| {
                let t = k as f64 * DT;
                r.step(Some(&[(20.0 * t).sin(), 0.5 * (13.0 * t).cos()]))
                    .unwrap();
                state(&r)
            })
            .collect::<Vec<_>>()
    };
    let (a, b) = (run(&base), run(&delayed));
    for (k, s) in b.iter().take(n).enumerate() {
        assert_eq!(*s, ([0.5, -0.5], [0.0; 2]), "step {k}: nothing applied yet");
    }
    for k in 0..40 - n {
        assert_eq!(b[k + n], a[k], "step {k}");
    }
}

/// A command beyond the effort limit is clipped to it: the arm moves as
/// under the limit itself, and the applied torque and the flag say so.
#[test]
fn saturation_clips_at_the_limit() {
    let limited = config(|c| c.effort_limit = Some(PerJoint::Each(vec![5.0, 2.0])));
    let q = [0.1, 0.2];
    let mut r = rig(&limited, 0);
    let a = mean_accel(&mut r, q, [0.0; 2], [100.0, -100.0]);
    assert_eq!(r.applied_torque(), [5.0, -2.0]);
    assert!(r.effects().has(Effects::SATURATED));
    let b = mean_accel(&mut rig(&limited, 0), q, [0.0; 2], [5.0, -2.0]);
    assert_eq!(a, b);
    let mut r = rig(&limited, 0);
    mean_accel(&mut r, q, [0.0; 2], [4.0, -1.0]);
    assert!(!r.effects().has(Effects::SATURATED));
}

/// d enters eq. 1 beside τ: a disturbance d with command τ moves the arm
/// exactly as the command τ + d does without one.
#[test]
fn a_disturbance_adds_to_the_joint_torque() {
    let d = [1.5, -0.7];
    let with = config(|c| c.disturbance.constant = PerJoint::Each(d.to_vec()));
    let q = [0.3, 0.4];
    let tau = [2.0, 1.0];
    let mut r = rig(&with, 0);
    let a = mean_accel(&mut r, q, [0.1, -0.2], tau);
    assert_eq!(r.disturbance(), d);
    assert!(r.effects().has(Effects::DISTURBANCE));
    let b = mean_accel(
        &mut rig(&PlantConfig::default(), 0),
        q,
        [0.1, -0.2],
        [tau[0] + d[0], tau[1] + d[1]],
    );
    for i in 0..2 {
        assert!((a[i] - b[i]).abs() < 1e-12, "{a:?} vs {b:?}");
    }
}

/// The sensors report the state plus noise of the set std, and never
/// change the state itself.
#[test]
fn sensor_noise_has_the_set_standard_deviation() {
    let c = config(|c| {
        c.gravity = [0.0; 3];
        c.sensor.q_noise_std = PerJoint::Each(vec![0.002, 0.0]);
        c.sensor.qd_noise_std = PerJoint::All(0.05);
    });
    let mut r = rig(&c, 11);
    r.set_state(&[0.5, 0.25], &[0.0; 2]).unwrap();
    let (mut sq, mut sqd, n) = (0.0, 0.0, 40_000);
    for _ in 0..n {
        let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
        r.measure_into(&mut q, &mut qd);
        assert_eq!(q[1], 0.25);
        sq += (q[0] - 0.5).powi(2);
        sqd += qd[0].powi(2) + qd[1].powi(2);
    }
    assert_eq!(state(&r), ([0.5, 0.25], [0.0; 2]));
    // 40 000 (80 000) draws: the sample std is within 1 % with odds > 1e-6.
    assert!(((sq / n as f64).sqrt() / 0.002 - 1.0).abs() < 0.01);
    assert!(((sqd / (2 * n) as f64).sqrt() / 0.05 - 1.0).abs() < 0.01);
    assert!(r.effects().has(Effects::SENSOR_NOISE));
}

#[test]
fn lost_commands_leave_the_last_one_held() {
    let all_lost = config(|c| c.actuation.drop_probability = 1.0);
    let mut r = rig(&all_lost, 0);
    r.step(Some(&[3.0, 3.0])).unwrap();
    assert_eq!(r.applied_torque(), [0.0, 0.0]);
    assert!(
        r.effects()
            .has(Effects::COMMAND_DROPPED | Effects::COMMAND_HELD)
    );
    let mut r = rig(&PlantConfig::default(), 0);
    r.step(Some(&[3.0, 3.0])).unwrap();
    r.step(None).unwrap();
    assert_eq!(r.applied_torque(), [3.0, 3.0]);
    assert!(r.effects().has(Effects::COMMAND_HELD));
    assert!(!r.effects().has(Effects::COMMAND_DROPPED));
}

/// Every random effect on: the same seed gives the same readings and
/// motion to the bit; another seed does not.
#[test]
fn seeded_rigs_reproduce_exactly_and_seeds_differ() {
    let c = config(|c| {
        c.sensor.q_noise_std = PerJoint::All(1e-3);
        c.sensor.qd_noise_std = PerJoint::All(1e-2);
        c.sensor.q_resolution = PerJoint::All(std::f64::consts::TAU / 4096.0);
        c.disturbance.noise_std = PerJoint::All(0.5);
        c.actuation.drop_probability = 0.1;
    });
    let run = |seed| {
        let mut r = rig(&c, seed);
        r.set_state(&[0.6, 1.8], &[0.0; 2]).unwrap();
        let mut out = Vec::new();
        for _ in 0..300 {
            let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
            r.measure_into(&mut q, &mut qd);
            let g = common::gravity(q);
            r.step(Some(&g)).unwrap();
            out.push((q, qd, state(&r), r.effects()));
        }
        out
    };
    let a = run(42);
    assert_eq!(a, run(42));
    assert_ne!(a, run(43));
    assert!(a.iter().any(|x| x.3.has(Effects::COMMAND_DROPPED)));
}
