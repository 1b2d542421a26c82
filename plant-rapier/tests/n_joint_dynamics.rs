//! The plant (both engines) for n > 2 against an independent recursive Newton-Euler
//! evaluation of the same URDF (`arm_model::dynamics`, written from the
//! model's kinematic and inertial data; nothing of Rapier's is used). The
//! model-based controller laws use that same code, so this test checks
//! their model too.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

mod common;

use arm_model::dynamics::Dynamics;
use plant_rapier::{ArmModel, EngineName, JointKind, Plant, PlantConfig};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Inverse dynamics of `arm_model::dynamics` (the model-based laws' model)
/// plus the URDF damping the plant applies: Jᵀ(M q̈ + C q̇ + G + D q̇) of
/// the full tree, J the mimic coupling's Jacobian.
fn rnea(m: &ArmModel, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let mut tau = Dynamics::new(m, 1.0).inverse(q, qd, qdd).to_vec();
    for (k, &ji) in m.actuated.iter().enumerate() {
        tau[k] += m.joints[ji].damping * qd[k];
    }
    for c in &m.mimic {
        let v = c.multiplier * qd[c.leader];
        tau[c.leader] += c.multiplier * m.joints[c.joint].damping * v;
    }
    tau
}

/// Both engines against the reference.
fn check(urdf: &str, seed: u64) {
    check_engine(urdf, seed, EngineName::Articulated);
    check_engine(urdf, seed, EngineName::Rapier);
}

fn check_engine(urdf: &str, seed: u64, engine: EngineName) {
    let model = ArmModel::from_urdf_str(urdf).unwrap();
    let n = model.dof();
    // URDF damping stays on (it is in the reference dynamics); dry friction
    // is not a smooth force, so it is off here.
    let model = common::with_joints(&model, |j| j.friction = 0.0);
    let config = PlantConfig {
        engine,
        saturate: false,
        ..PlantConfig::default()
    };
    // At rest the damping force grows with the velocity during the step, so
    // the static checks are made without it; the moving one keeps it.
    let still = common::with_joints(&model, |j| j.damping = 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let dt = 1e-3;
    for _ in 0..20 {
        // Inside the joint limits: at a limit Rapier's stop acts, which the
        // rigid-body equations do not model.
        let q: Vec<f64> = model
            .actuated
            .iter()
            .map(|&j| {
                let (lo, hi) = model.joints[j].limits.unwrap_or((-2.5, 2.5));
                let (lo, hi) = (lo.max(-2.5), hi.min(2.5));
                let pad = 0.05 * (hi - lo);
                rng.random_range(lo + pad..hi - pad)
            })
            .collect();
        let zero = vec![0.0; n];
        let g = rnea(&still, &q, &zero, &zero);
        // Gravity holds the arm still (exactly: at rest with τ = G the true
        // acceleration is zero throughout the step).
        let mut p = Plant::new(&still, &config).unwrap();
        p.set_state(&q, &zero).unwrap();
        p.step(&g, dt).unwrap();
        let v = p.state().1;
        assert!(
            v.iter().all(|v| (v / dt).abs() < 1e-6),
            "{} ({engine:?}): gravity at {q:?}: {v:?}",
            model.name
        );
        // τ = G + M e_k gives unit acceleration of joint k at the start of
        // the step. Over a 0.1 ms step the posture moves by 5e-9 rad, so the
        // mean acceleration differs by parts in 1e-6 (tolerance 1e-4 rad/s²;
        // over 1 ms the iiwa's light wrist, λmax(M⁻¹) ≈ 1000, turns that
        // drift into 1.1e-4).
        for k in 0..n {
            let mut e = zero.clone();
            e[k] = 1.0;
            let tau = rnea(&still, &q, &zero, &e);
            let mut p = Plant::new(&still, &config).unwrap();
            p.set_state(&q, &zero).unwrap();
            p.step(&tau, dt / 10.0).unwrap();
            let acc: Vec<f64> = p.state().1.iter().map(|v| v / (dt / 10.0)).collect();
            // In Rapier a mimic coupling is a solver constraint (one
            // iteration per substep): accelerating a leader is exact to 2e-2
            // only. The articulated engine reduces it into the leader.
            let rapier = engine == EngineName::Rapier;
            let tol = if rapier && still.mimic.iter().any(|c| c.leader == k) {
                2e-2
            } else {
                1e-4
            };
            for i in 0..n {
                let want = if i == k { 1.0 } else { 0.0 };
                assert!(
                    (acc[i] - want).abs() < tol,
                    "{} ({engine:?}): column {k} at {q:?}: {acc:?}",
                    model.name
                );
            }
        }
        // Moving: τ = C q̇ + G (zero acceleration wanted at the start); the
        // state's drift over the step (and Rapier's first-order error) then
        // leaves O(dt) residue, bounded by 1e-2 of the Coriolis/centrifugal
        // acceleration scale.
        let qd: Vec<f64> = (0..n).map(|_| rng.random_range(-1.5..1.5)).collect();
        let qd: Vec<f64> = qd
            .iter()
            .enumerate()
            .map(|(k, v)| v * speed_scale(&model, k))
            .collect();
        let tau = rnea(&model, &q, &qd, &zero);
        let mut p = Plant::new(&model, &config).unwrap();
        p.set_state(&q, &qd).unwrap();
        p.step(&tau, dt).unwrap();
        let dv: Vec<f64> = p
            .state()
            .1
            .iter()
            .zip(&qd)
            .map(|(a, b)| (a - b) / dt)
            .collect();
        let scale: f64 = qd.iter().map(|v| v * v).sum::<f64>() * 10.0 + 1.0;
        assert!(
            dv.iter().all(|a| a.abs() < 1e-2 * scale),
            "{} ({engine:?}): C q̇ at {q:?}, {qd:?}: {dv:?}",
            model.name
        );
    }
}

#[test]
fn three_link_planar_matches_newton_euler() {
    check(include_str!("../../robots/three_link_planar.urdf"), 5);
}

#[test]
fn ur5_matches_newton_euler() {
    check(include_str!("../../robots/ur5.urdf"), 6);
}

#[test]
fn iiwa14_matches_newton_euler() {
    check(include_str!("../../robots/iiwa14.urdf"), 7);
}

#[test]
fn two_link_matches_newton_euler() {
    check(include_str!("../../robots/two_link.urdf"), 7);
}

/// Prismatic fingers move centimetres: scale their random speed to the range.
fn speed_scale(m: &ArmModel, k: usize) -> f64 {
    let j = &m.joints[m.actuated[k]];
    match (j.kind, j.limits) {
        (JointKind::Prismatic, Some((lo, hi))) => (hi - lo).min(1.0),
        _ => 1.0,
    }
}

#[test]
fn panda_with_mimic_fingers_and_damping_matches_newton_euler() {
    let m = ArmModel::from_urdf_str(include_str!("../../robots/panda.urdf")).unwrap();
    assert_eq!(m.mimic.len(), 1);
    assert!(m.has_urdf_dynamics());
    check(include_str!("../../robots/panda.urdf"), 8);
}

#[test]
fn xarm7_matches_newton_euler() {
    check(include_str!("../../robots/xarm7.urdf"), 9);
}

#[test]
fn so101_matches_newton_euler() {
    check(include_str!("../../robots/so101.urdf"), 10);
}

#[test]
fn z1_matches_newton_euler() {
    check(include_str!("../../robots/z1.urdf"), 11);
}

/// A torso with a head and two four-joint arms, and a gripper whose second
/// finger mimics the first: a tree, so the inertia's factor is made leaves
/// first on the branches' pattern. Light damped wrists put some joints in
/// the damping's modes and leave the others explicit. `cross`: the head's
/// nod also mimics the left wrist, a coupling across branches; the head
/// comes first in tree order, so it is eliminated after the arm, and
/// eliminating the wrist fills in the arm's joints × the neck.
fn upper_body(cross: bool) -> String {
    // (joint, kind, parent link, child link, child mass, origin, axis, damping, mimic)
    type Row = (
        String,
        &'static str,
        String,
        String,
        f64,
        String,
        &'static str,
        f64,
        &'static str,
    );
    let row = |j: &str, kind, p: &str, c: &str, mass, xyz: &str, axis, damping, mimic| -> Row {
        (
            j.into(),
            kind,
            p.into(),
            c.into(),
            mass,
            xyz.into(),
            axis,
            damping,
            mimic,
        )
    };
    let mut joints = vec![
        row(
            "waist", "revolute", "base", "torso", 8.0, "0 0 0.3", "0 0 1", 0.5, "",
        ),
        row(
            "neck", "revolute", "torso", "head", 1.2, "0 0 0.5", "0 0 1", 0.2, "",
        ),
    ];
    if cross {
        joints.push(row(
            "nod",
            "revolute",
            "head",
            "visor",
            0.3,
            "0.05 0 0.1",
            "0 1 0",
            0.3,
            "l_j3",
        ));
    }
    for (side, y) in [("l", 0.2), ("r", -0.2)] {
        let arm = [
            ("0 1 0", 2.0, 0.5),
            ("1 0 0", 1.5, 0.0),
            ("0 1 0", 1.0, 1.0),
            ("0 0 1", 0.05, 2.0),
        ];
        for (k, (axis, mass, damping)) in arm.into_iter().enumerate() {
            let (parent, xyz) = match k {
                0 => ("torso".to_string(), format!("0 {y} 0.4")),
                _ => (format!("{side}_link{}", k - 1), "0 0 0.25".to_string()),
            };
            let (joint, child) = (format!("{side}_j{k}"), format!("{side}_link{k}"));
            joints.push(row(
                &joint, "revolute", &parent, &child, mass, &xyz, axis, damping, "",
            ));
        }
    }
    joints.push(row(
        "finger_a_joint",
        "prismatic",
        "l_link3",
        "finger_a",
        0.02,
        "0 0.02 0.05",
        "0 1 0",
        1.0,
        "",
    ));
    joints.push(row(
        "finger_b_joint",
        "prismatic",
        "l_link3",
        "finger_b",
        0.02,
        "0 -0.02 0.05",
        "0 1 0",
        1.0,
        "finger_a_joint",
    ));
    let mut s = String::from(r#"<robot name="upper_body"><link name="base"/>"#);
    for (name, kind, parent, child, mass, xyz, axis, damping, mimic) in joints {
        let i = 0.02 * mass;
        let mimic = match mimic {
            "" => String::new(),
            "finger_a_joint" => format!(r#"<mimic joint="{mimic}" multiplier="-1"/>"#),
            _ => format!(r#"<mimic joint="{mimic}" multiplier="0.5" offset="0.1"/>"#),
        };
        s += &format!(
            r#"<link name="{child}"><inertial><origin xyz="0.02 0.01 0.05"/><mass value="{mass}"/><inertia ixx="{i}" ixy="0.0001" ixz="0" iyy="{i}" iyz="0" izz="{}"/></inertial></link>
<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><origin xyz="{xyz}" rpy="0.1 0 0.2"/><axis xyz="{axis}"/><limit lower="-2" upper="2" effort="500" velocity="3"/><dynamics damping="{damping}"/>{mimic}</joint>
"#,
            0.8 * i
        );
    }
    s + "</robot>"
}

#[test]
fn a_branched_upper_body_matches_newton_euler() {
    let m = ArmModel::from_urdf_str(&upper_body(false)).unwrap();
    assert_eq!((m.dof(), m.mimic.len()), (11, 1));
    check(&upper_body(false), 12);
}

#[test]
fn a_mimic_across_branches_matches_newton_euler() {
    let m = ArmModel::from_urdf_str(&upper_body(true)).unwrap();
    assert_eq!((m.dof(), m.mimic.len()), (11, 2));
    // Rapier's mimic is a solver constraint: only the articulated engine
    // is exact for a coupling across branches.
    check_engine(&upper_body(true), 13, EngineName::Articulated);
}
