//! The paper's two-link arm in closed form (SPEC §1) and an RK4 integrator,
//! written independently of Rapier to check the plant against.

#![allow(
    dead_code,
    reason = "shared by several test binaries; each uses only some of it"
)]

pub const M1: f64 = 2.0;
pub const M2: f64 = 0.85;
pub const L1: f64 = 0.35;
pub const LC1: f64 = 0.175;
pub const LC2: f64 = 0.155;
pub const I1: f64 = 0.06125;
pub const I2: f64 = 0.02042;
pub const G: f64 = 9.81;

pub fn mass(q: [f64; 2]) -> [[f64; 2]; 2] {
    let c2 = q[1].cos();
    let m11 = I1 + I2 + M1 * LC1 * LC1 + M2 * (L1 * L1 + LC2 * LC2 + 2.0 * L1 * LC2 * c2);
    let m12 = I2 + M2 * (LC2 * LC2 + L1 * LC2 * c2);
    let m22 = I2 + M2 * LC2 * LC2;
    [[m11, m12], [m12, m22]]
}

pub fn gravity(q: [f64; 2]) -> [f64; 2] {
    let g2 = M2 * LC2 * G * (q[0] + q[1]).cos();
    [(M1 * LC1 + M2 * L1) * G * q[0].cos() + g2, g2]
}

pub fn coriolis_times_qd(q: [f64; 2], qd: [f64; 2]) -> [f64; 2] {
    let h = -M2 * L1 * LC2 * q[1].sin();
    [
        h * qd[1] * qd[0] + h * (qd[0] + qd[1]) * qd[1],
        -h * qd[0] * qd[0],
    ]
}

/// q̈ = M⁻¹ (τ − C q̇ − G).
pub fn accel(q: [f64; 2], qd: [f64; 2], tau: [f64; 2]) -> [f64; 2] {
    let m = mass(q);
    let c = coriolis_times_qd(q, qd);
    let g = gravity(q);
    let b = [tau[0] - c[0] - g[0], tau[1] - c[1] - g[1]];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [
        (m[1][1] * b[0] - m[0][1] * b[1]) / det,
        (m[0][0] * b[1] - m[1][0] * b[0]) / det,
    ]
}

/// One RK4 step of the closed form with τ held.
pub fn rk4_step(q: [f64; 2], qd: [f64; 2], tau: [f64; 2], h: f64) -> ([f64; 2], [f64; 2]) {
    let f = |q: [f64; 2], v: [f64; 2]| (v, accel(q, v, tau));
    let add = |a: [f64; 2], b: [f64; 2], s: f64| [a[0] + s * b[0], a[1] + s * b[1]];
    let (k1q, k1v) = f(q, qd);
    let (k2q, k2v) = f(add(q, k1q, h / 2.0), add(qd, k1v, h / 2.0));
    let (k3q, k3v) = f(add(q, k2q, h / 2.0), add(qd, k2v, h / 2.0));
    let (k4q, k4v) = f(add(q, k3q, h), add(qd, k3v, h));
    let comb = |x: [f64; 2], a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]| {
        [
            x[0] + h / 6.0 * (a[0] + 2.0 * b[0] + 2.0 * c[0] + d[0]),
            x[1] + h / 6.0 * (a[1] + 2.0 * b[1] + 2.0 * c[1] + d[1]),
        ]
    };
    (comb(q, k1q, k2q, k3q, k4q), comb(qd, k1v, k2v, k3v, k4v))
}

/// RK4 over `t` seconds in `steps` steps.
pub fn rk4(q: [f64; 2], qd: [f64; 2], tau: [f64; 2], t: f64, steps: usize) -> ([f64; 2], [f64; 2]) {
    let h = t / steps as f64;
    let (mut q, mut qd) = (q, qd);
    for _ in 0..steps {
        (q, qd) = rk4_step(q, qd, tau, h);
    }
    (q, qd)
}

/// Total mechanical energy (kinetic + potential, z up).
pub fn energy(q: [f64; 2], qd: [f64; 2]) -> f64 {
    let m = mass(q);
    let ke =
        0.5 * (m[0][0] * qd[0] * qd[0] + 2.0 * m[0][1] * qd[0] * qd[1] + m[1][1] * qd[1] * qd[1]);
    let pe = M1 * G * LC1 * q[0].sin() + M2 * G * (L1 * q[0].sin() + LC2 * (q[0] + q[1]).sin());
    ke + pe
}

/// `model` with `edit` applied to every joint (dry friction or damping off).
pub fn with_joints(
    model: &plant_rapier::ArmModel,
    edit: impl Fn(&mut plant_rapier::JointInfo),
) -> plant_rapier::ArmModel {
    let mut m = model.clone();
    m.joints.iter_mut().for_each(edit);
    m
}
