//! The torque bounds and the robust margin of `cbf-ctc` and `mpc`
//! (BASELINES §3), checked against what they are meant to do rather than
//! against their own formulas: the box by its defining property, the
//! bounded filter by a projection computed another way, and both laws'
//! torques against the effort limits.

#![allow(
    clippy::unwrap_used,
    reason = "test code: a broken expectation should fail loudly"
)]

use super::*;
use crate::LawName;
use crate::law_table::LawKind;
use arm_model::TWO_LINK_URDF;

/// The two-link arm with 30 N m motors, so that the bounds act.
fn weak_arm() -> ArmModel {
    ArmModel::from_urdf_str(&TWO_LINK_URDF.replace("effort=\"500\"", "effort=\"30\"")).unwrap()
}

const EFFORT: f64 = 30.0;

struct Lcg(u64);

impl Lcg {
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// One random state: q, q̇, the reference (q_d, q̇_d, q̈_d) and e near a
/// 0.05 rad envelope, either inside or outside, heading either way.
struct State {
    q: [f64; 2],
    qd: [f64; 2],
    q_d: [f64; 2],
    qd_d: [f64; 2],
    qdd_d: [f64; 2],
}

impl State {
    fn random(rng: &mut Lcg) -> Self {
        let q_d = [rng.range(-1.5, 1.5), rng.range(-1.5, 1.5)];
        let e = [rng.range(-0.08, 0.08), rng.range(-0.08, 0.08)];
        let ed = [
            e[0].signum() * rng.range(-3.0, 3.0),
            e[1].signum() * rng.range(-3.0, 3.0),
        ];
        let qd_d = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
        Self {
            q: [q_d[0] + e[0], q_d[1] + e[1]],
            qd: [qd_d[0] + ed[0], qd_d[1] + ed[1]],
            q_d,
            qd_d,
            qdd_d: [rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)],
        }
    }
    fn input(&self) -> ControllerInput<'_> {
        ControllerInput {
            t: 1.0,
            q: &self.q,
            qd: &self.qd,
            q_d: &self.q_d,
            qd_d: &self.qd_d,
            qdd_d: &self.qdd_d,
            kc: &[0.05, 0.05],
            kc_dot: &[0.0, 0.0],
        }
    }
}

/// M(q) as a matrix and h(q, q̇), from the model's inverse dynamics.
fn mass_and_bias(d: &mut Dynamics, q: &[f64], qd: &[f64]) -> (nalgebra::Matrix2<f64>, [f64; 2]) {
    let g = d.gravity(q).to_vec();
    let c0 = d.inverse(q, &[0.0, 0.0], &[1.0, 0.0]).to_vec();
    let c1 = d.inverse(q, &[0.0, 0.0], &[0.0, 1.0]).to_vec();
    let m = nalgebra::Matrix2::new(c0[0] - g[0], c1[0] - g[0], c0[1] - g[1], c1[1] - g[1]);
    let h = d.inverse(q, qd, &[0.0, 0.0]).to_vec();
    (m, [h[0], h[1]])
}

/// The largest |τ_i| over the box's corners.
fn worst_corner(m: &nalgebra::Matrix2<f64>, h: [f64; 2], qdd_d: [f64; 2], a: &[f64]) -> f64 {
    let mut worst = 0.0f64;
    for (s0, s1) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
        let acc = nalgebra::Vector2::new(qdd_d[0] + s0 * a[0], qdd_d[1] + s1 * a[1]);
        let tau = m * acc + nalgebra::Vector2::new(h[0], h[1]);
        worst = worst.max(tau[0].abs()).max(tau[1].abs());
    }
    worst
}

#[test]
fn the_torque_box_reaches_the_limits_and_no_further() {
    let model = weak_arm();
    let mut dynamics = Dynamics::new(&model, 1.0);
    let mut b = TorqueBox::new(&model).unwrap();
    let mut rng = Lcg(5);
    let mut tested = 0;
    for _ in 0..200 {
        let s = State::random(&mut rng);
        b.update(&mut dynamics, &s.q, &s.qd, &s.qdd_d);
        let a = b.half_widths().to_vec();
        let (m, h) = mass_and_bias(&mut dynamics, &s.q, &s.qd);
        let worst = worst_corner(&m, h, s.qdd_d, &a);
        if a.iter().all(|&x| x == 0.0) {
            // Only when the feedforward alone breaks a limit.
            let tau0 = m * nalgebra::Vector2::new(s.qdd_d[0], s.qdd_d[1]);
            assert!(
                (tau0[0] + h[0]).abs() >= EFFORT || (tau0[1] + h[1]).abs() >= EFFORT,
                "an empty box at {:?}",
                s.q
            );
            continue;
        }
        tested += 1;
        assert!(worst <= EFFORT * (1.0 + 1e-12), "a corner asks {worst} N m");
        // A box 1e-6 larger in the same proportions breaks a limit: it is
        // the largest of its shape.
        let grown: Vec<f64> = a.iter().map(|x| x * (1.0 + 1e-6)).collect();
        assert!(
            worst_corner(&m, h, s.qdd_d, &grown) > EFFORT,
            "{a:?} is not the largest"
        );
    }
    assert!(tested > 100, "{tested} states had room");
}

fn feedback(law: LawName, model: &ArmModel, set: impl Fn(&mut ControllerParams)) -> Feedback {
    let mut p = ControllerParams {
        law,
        tc: 0.5,
        ..Default::default()
    };
    set(&mut p);
    let LawKind::Feedback(kind) = law.kind() else {
        panic!("{law} is not a feedback law")
    };
    Feedback::new(&p, kind, 2, Some(model)).unwrap()
}

/// Dykstra's alternating projections of `u` onto {x: 2 e x ≤ b} ∩ [−a, a]
/// (the exact projection onto an intersection of convex sets, reached
/// iteratively): an independent way to the filter's closed form.
fn dykstra(u: f64, e: f64, b: f64, a: f64) -> f64 {
    let half = |x: f64| match e {
        e if e > 0.0 => x.min(b / (2.0 * e)),
        e if e < 0.0 => x.max(b / (2.0 * e)),
        _ => x,
    };
    let (mut x, mut p, mut q) = (u, 0.0, 0.0);
    for _ in 0..10_000 {
        let y = half(x + p);
        p += x - y;
        let next = (y + q).clamp(-a, a);
        q += y - next;
        x = next;
    }
    x
}

#[test]
fn the_bounded_robust_filter_is_the_projection_onto_its_rows() {
    let model = weak_arm();
    // A fast rate (λ = 100) leaves the row loose enough inside the
    // envelope for the box to be what binds on some states.
    let (lambda, margin) = (100.0, 40.0);
    let mut law = feedback(LawName::CbfCtc, &model, |p| {
        p.cbf_margin = margin;
        p.cbf_rate = lambda;
        p.torque_bounds = true;
    });
    let mut dynamics = Dynamics::new(&model, 1.0);
    let (kp, kd) = (225.0, 30.0);
    let mut rng = Lcg(11);
    let (mut boxed, mut margined, mut compared) = (0, 0, 0);
    for _ in 0..800 {
        let s = State::random(&mut rng);
        let mut out = Diagnostics::new(2);
        law.step(&s.input(), &mut out);
        let a = law.torque_box.as_ref().unwrap().half_widths().to_vec();
        let (m, h) = mass_and_bias(&mut dynamics, &s.q, &s.qd);
        let mut u = [0.0; 2];
        let mut feasible = true;
        let (mut box_acts, mut margin_acts) = (false, false);
        for i in 0..2 {
            let (e, ed) = (s.q[i] - s.q_d[i], s.qd[i] - s.qd_d[i]);
            let u_nom = -kd * ed - kp * e;
            let hd = -2.0 * e * ed;
            let b = -2.0 * ed * ed + 2.0 * lambda * hd + lambda * lambda * (0.0025 - e * e);
            let robust = b - 2.0 * e.abs() * margin;
            // The interval [−a, a] ∩ {2 e u ≤ robust} is not empty.
            let row = robust / (2.0 * e);
            feasible &= (e <= 0.0 || row >= -a[i]) && (e >= 0.0 || row <= a[i]);
            u[i] = dykstra(u_nom, e, robust, a[i]);
            // The box changed the answer: the half-space alone gives another.
            box_acts |= (dykstra(u_nom, e, robust, f64::INFINITY) - u[i]).abs() > 1e-6;
            margin_acts |= 2.0 * e * u_nom <= b && 2.0 * e * u_nom > robust;
        }
        if !feasible {
            continue;
        }
        compared += 1;
        boxed += usize::from(box_acts);
        margined += usize::from(margin_acts);
        let tau = m * nalgebra::Vector2::new(s.qdd_d[0] + u[0], s.qdd_d[1] + u[1]);
        for i in 0..2 {
            let want = tau[i] + h[i];
            assert!(
                (out.tau[i] - want).abs() <= 1e-6 * want.abs().max(1.0),
                "{i}: law {}, projection {want}",
                out.tau[i]
            );
            assert!(out.tau[i].abs() <= EFFORT * (1.0 + 1e-9));
        }
    }
    assert!(compared > 120, "{compared} feasible states");
    assert!(
        boxed > 50 && margined > 10,
        "compared {compared}: box acted {boxed}, margin acted {margined}"
    );
}

#[test]
fn bounded_laws_keep_the_torque_within_the_effort_limits() {
    let model = weak_arm();
    for law in [LawName::Mpc, LawName::CbfCtc] {
        let mut bounded = feedback(law, &model, |p| p.torque_bounds = true);
        let mut free = feedback(law, &model, |p| p.torque_bounds = false);
        let mut dynamics = Dynamics::new(&model, 1.0);
        let mut rng = Lcg(17);
        let (mut checked, mut free_over) = (0, 0);
        for _ in 0..200 {
            let s = State::random(&mut rng);
            let (m, h) = mass_and_bias(&mut dynamics, &s.q, &s.qd);
            let tau0 = m * nalgebra::Vector2::new(s.qdd_d[0], s.qdd_d[1]);
            if (tau0[0] + h[0]).abs() >= EFFORT || (tau0[1] + h[1]).abs() >= EFFORT {
                continue; // the feedforward alone breaks a limit
            }
            let (mut a, mut b) = (Diagnostics::new(2), Diagnostics::new(2));
            bounded.step(&s.input(), &mut a);
            free.step(&s.input(), &mut b);
            checked += 1;
            let peak = a.tau.iter().fold(0.0f64, |m, t| m.max(t.abs()));
            assert!(peak <= EFFORT * (1.0 + 1e-9), "{law}: {:?}", a.tau);
            free_over += usize::from(b.tau.iter().any(|t| t.abs() > EFFORT));
        }
        assert!(checked > 100, "{law}: {checked} states");
        assert!(
            free_over > 20,
            "{law}: unbounded, {free_over} states exceed the limits"
        );
    }
}
