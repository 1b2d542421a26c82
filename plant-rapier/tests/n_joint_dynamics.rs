//! The plant for n > 2 against an independent recursive Newton-Euler
//! evaluation of the same URDF, written here from the model's kinematic and
//! inertial data (nothing of Rapier's is used).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use nalgebra::{Isometry3, Matrix3, Point3, Translation3, UnitQuaternion, Vector3};
use plant_rapier::{ArmModel, JointKind, Origin, Plant, PlantConfig};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const G: Vector3<f64> = Vector3::new(0.0, 0.0, -9.81);

fn iso(o: &Origin) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(o.xyz[0], o.xyz[1], o.xyz[2]),
        UnitQuaternion::from_euler_angles(o.rpy[0], o.rpy[1], o.rpy[2]),
    )
}

/// The coordinates of every moving joint (controlled, then mimic) from the
/// controlled ones: q_f = multiplier · q_leader (+ offset for positions).
fn expand(m: &ArmModel, x: &[f64], offset: bool) -> Vec<f64> {
    let mut out = x.to_vec();
    for c in &m.mimic {
        out.push(c.multiplier * x[c.leader] + if offset { c.offset } else { 0.0 });
    }
    out
}

/// Inverse dynamics in the controlled joints' coordinates, mimic couplings
/// and URDF damping included: the generalised force Jᵀ(M q̈ + C q̇ + G + D q̇)
/// of the full tree, with J the coupling's Jacobian.
fn rnea(m: &ArmModel, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let (qf, qdf, qddf) = (
        expand(m, q, true),
        expand(m, qd, false),
        expand(m, qdd, false),
    );
    let full = rnea_full(m, &qf, &qdf, &qddf);
    let moving: Vec<usize> = m.moving_joints().collect();
    let mut tau: Vec<f64> = (0..m.dof())
        .map(|k| full[k] + m.joints[moving[k]].damping * qdf[k])
        .collect();
    for (i, c) in m.mimic.iter().enumerate() {
        let k = m.dof() + i;
        tau[c.leader] += c.multiplier * (full[k] + m.joints[c.joint].damping * qdf[k]);
    }
    tau
}

/// Inverse dynamics τ = M(q) q̈ + C(q, q̇) q̇ + G(q) of every moving joint,
/// all in the world frame.
fn rnea_full(m: &ArmModel, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let nl = m.links.len();
    let mut pose = vec![Isometry3::identity(); nl];
    let mut w = vec![Vector3::zeros(); nl];
    let mut wd = vec![Vector3::zeros(); nl];
    // Linear acceleration of each link frame's origin.
    let mut a = vec![Vector3::zeros(); nl];
    let mut axis_w = vec![Vector3::zeros(); m.joints.len()];
    let moving: Vec<usize> = m.moving_joints().collect();
    let dof_of = |ji: usize| moving.iter().position(|&a| a == ji);
    for &ji in &m.topological {
        let j = &m.joints[ji];
        let (p, c) = (j.parent, j.child);
        let k = dof_of(ji).unwrap();
        let ax = Vector3::new(j.axis[0], j.axis[1], j.axis[2]);
        let motion = match j.kind {
            JointKind::Prismatic => Isometry3::translation(ax.x * q[k], ax.y * q[k], ax.z * q[k]),
            _ => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_scaled_axis(ax * q[k]),
            ),
        };
        pose[c] = pose[p] * iso(&j.origin) * motion;
        let z = pose[c].rotation * ax;
        axis_w[ji] = z;
        let r = pose[c].translation.vector - pose[p].translation.vector;
        match j.kind {
            JointKind::Prismatic => {
                w[c] = w[p];
                wd[c] = wd[p];
                a[c] = a[p]
                    + wd[p].cross(&r)
                    + w[p].cross(&w[p].cross(&r))
                    + z * qdd[k]
                    + 2.0 * w[p].cross(&(z * qd[k]));
            }
            _ => {
                w[c] = w[p] + z * qd[k];
                wd[c] = wd[p] + z * qdd[k] + w[p].cross(&(z * qd[k]));
                a[c] = a[p] + wd[p].cross(&r) + w[p].cross(&w[p].cross(&r));
            }
        }
    }
    // Backward pass: force and moment (about the link frame origin) each
    // link's joint must supply.
    let mut f = vec![Vector3::zeros(); nl];
    let mut n = vec![Vector3::zeros(); nl];
    for (li, l) in m.links.iter().enumerate() {
        if li == m.root {
            continue;
        }
        let io = iso(&l.inertial_origin);
        let com = pose[li] * Point3::from(io.translation.vector);
        let rc = com.coords - pose[li].translation.vector;
        let [ixx, ixy, ixz, iyy, iyz, izz] = l.inertia;
        let i_local = Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
        let rot = (pose[li].rotation * io.rotation).to_rotation_matrix();
        let i_w = rot.matrix() * i_local * rot.matrix().transpose();
        let a_com = a[li] + wd[li].cross(&rc) + w[li].cross(&w[li].cross(&rc));
        let fi = l.mass * (a_com - G);
        f[li] = fi;
        n[li] = rc.cross(&fi) + i_w * wd[li] + w[li].cross(&(i_w * w[li]));
    }
    let mut tau = vec![0.0; moving.len()];
    for &ji in m.topological.iter().rev() {
        let j = &m.joints[ji];
        let (p, c) = (j.parent, j.child);
        let k = dof_of(ji).unwrap();
        tau[k] = match j.kind {
            JointKind::Prismatic => f[c].dot(&axis_w[ji]),
            _ => n[c].dot(&axis_w[ji]),
        };
        let r = pose[c].translation.vector - pose[p].translation.vector;
        let (fc, nc) = (f[c], n[c]);
        f[p] += fc;
        n[p] += nc + r.cross(&fc);
    }
    tau
}

fn check(urdf: &str, seed: u64) {
    let model = ArmModel::from_urdf_str(urdf).unwrap();
    let n = model.dof();
    // URDF damping stays on (it is in the reference dynamics); dry friction
    // is not a smooth force, so it is off here.
    let model = ArmModel {
        joints: model
            .joints
            .iter()
            .map(|j| plant_rapier::JointInfo {
                friction: 0.0,
                ..j.clone()
            })
            .collect(),
        ..model
    };
    let config = PlantConfig {
        saturate: false,
        ..PlantConfig::default()
    };
    // At rest the damping force grows with the velocity during the step, so
    // the static checks are made without it; the moving one keeps it.
    let still = ArmModel {
        joints: model
            .joints
            .iter()
            .map(|j| plant_rapier::JointInfo {
                damping: 0.0,
                ..j.clone()
            })
            .collect(),
        ..model.clone()
    };
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
            "{}: gravity at {q:?}: {v:?}",
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
            // A mimic coupling is a solver constraint (one iteration per
            // substep): accelerating a leader is exact to 2e-2 only.
            let tol = if still.mimic.iter().any(|c| c.leader == k) {
                2e-2
            } else {
                1e-4
            };
            for i in 0..n {
                let want = if i == k { 1.0 } else { 0.0 };
                assert!(
                    (acc[i] - want).abs() < tol,
                    "{}: column {k} at {q:?}: {acc:?}",
                    model.name
                );
            }
        }
        // Moving: τ = C q̇ + G (zero acceleration wanted at the start);
        // Rapier's first-order step then leaves O(dt) residue, bounded by
        // 1e-2 of the Coriolis/centrifugal acceleration scale.
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
            "{}: C q̇ at {q:?}, {qd:?}: {dv:?}",
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
