#![allow(
    clippy::unwrap_used,
    reason = "test code: a broken expectation should fail loudly"
)]
use super::*;

fn input<'a>(
    t: f64,
    e: &'a [f64],
    ed: &'a [f64],
    kc: &'a [f64],
    kc_dot: &'a [f64],
) -> MpcInput<'a> {
    MpcInput {
        t,
        e,
        ed,
        kc,
        kc_dot,
        u_max: None,
    }
}

/// How close the law's u₀ must be to an exact solution, relative: the
/// solver stops at its default duality gap (1e-8), up to 6e-4 off where a
/// row is active, and `Polish` makes it exact from the active rows.
const AGREES: f64 = 1e-9;

/// The nominal QP's shape: no input rows, no tightening.
fn nominal(horizon: usize, h: f64, tc: f64) -> MpcShape {
    MpcShape {
        horizon,
        h,
        tc,
        bounded: false,
        disturbance: 0.0,
    }
}

#[test]
fn its_unconstrained_gain_has_ctcs_poles_as_the_step_shrinks() {
    // s² + 30 s + 225: K_p = 225, K_d = 30, the default gains' ctc.
    for (h, tol) in [(0.01, 0.15), (0.001, 0.02)] {
        let qp = ErrorMpc::new(&[Weights::matching(225.0, 30.0)], nominal(20, h, 0.0)).unwrap();
        let [ke, kv] = qp.lqr()[0];
        assert!((ke / 225.0 - 1.0).abs() < tol, "h {h}: k_e {ke}");
        assert!((kv / 30.0 - 1.0).abs() < tol, "h {h}: k_v {kv}");
    }
}

#[test]
fn before_the_constraint_it_is_the_unconstrained_optimum() {
    let w = [
        Weights::matching(225.0, 30.0),
        Weights::matching(100.0, 25.0),
    ];
    let mut qp = ErrorMpc::new(&w, nominal(20, 0.01, 10.0)).unwrap();
    let (e, ed) = ([0.05, -0.02], [0.3, 0.1]);
    let x = input(0.0, &e, &ed, &[0.1, 0.1], &[0.0, 0.0]);
    let (u, breached) = qp.solve(&x);
    let u = u.to_vec();
    assert!(!breached);
    assert_eq!(qp.solves(), 0, "no constraint can act: no solver call");
    for i in 0..2 {
        let [ke, kv] = qp.lqr()[i];
        let want = -(ke * e[i] + kv * ed[i]);
        assert_eq!(u[i], want);
        // The solver, asked anyway, finds the same optimum.
        let solved = qp.solve_joint(i, &x).unwrap();
        assert!(
            (solved - want).abs() <= AGREES * want.abs().max(1.0),
            "{i}: {solved} vs {want}"
        );
    }
}

#[test]
fn an_active_envelope_bends_the_input() {
    let w = [Weights::matching(225.0, 30.0)];
    let mut qp = ErrorMpc::new(&w, nominal(20, 0.01, 0.0)).unwrap();
    // Heading out of a tight envelope fast: the QP brakes harder than LQR.
    let (e, ed) = ([0.009], [0.5]);
    let (u, breached) = qp.solve(&input(1.0, &e, &ed, &[0.01], &[0.0]));
    let u = u[0];
    let [ke, kv] = qp.lqr()[0];
    assert!(u < -(ke * e[0] + kv * ed[0]) - 1.0, "u {u}");
    assert!(!breached, "the envelope can be held");
    assert_eq!(qp.solves(), 1);
    // Already outside: the input is unbounded, so the QP brings e back
    // inside by the first predicted step, without slack.
    let (u, breached) = qp.solve(&input(1.0, &[0.1], &[0.0], &[0.01], &[0.0]));
    let e1 = 0.1 + 0.5 * 0.01 * 0.01 * u[0];
    assert!(e1.abs() <= 0.01 + 1e-9 && !breached, "e1 {e1}");
}

/// A small deterministic generator for the random states (the tests must
/// give the same states on every run).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// The same QP written independently: in the original variables
/// (e, ė, u), condensed onto u₀ … u_{N−1}, with its own Riccati terminal
/// cost and its own tightening (the worst vertex disturbance sequence),
/// solved exactly by enumerating active sets.
struct DenseQp {
    kp: f64,
    kd: f64,
    h: f64,
    horizon: usize,
}

impl DenseQp {
    fn a(&self) -> nalgebra::Matrix2<f64> {
        nalgebra::Matrix2::new(1.0, self.h, 0.0, 1.0)
    }
    fn b(&self) -> nalgebra::Vector2<f64> {
        nalgebra::Vector2::new(0.5 * self.h * self.h, self.h)
    }
    fn q(&self) -> nalgebra::Matrix2<f64> {
        let qv = (self.kd * self.kd - 2.0 * self.kp).max(0.0);
        nalgebra::Matrix2::new(self.kp * self.kp * self.h, 0.0, 0.0, qv * self.h)
    }

    /// P of the discrete Riccati equation and the LQR gain K (u = −K x).
    fn riccati(&self) -> (nalgebra::Matrix2<f64>, nalgebra::RowVector2<f64>) {
        let (a, b, q, r) = (self.a(), self.b(), self.q(), self.h);
        let mut p = q;
        for _ in 0..1_000_000 {
            let s = r + (b.transpose() * p * b)[0];
            let next =
                q + a.transpose() * p * a - a.transpose() * p * b * (b.transpose() * p * a) / s;
            let done = (next - p).abs().max() <= 1e-13 * next.abs().max();
            p = next;
            if done {
                break;
            }
        }
        let s = r + (b.transpose() * p * b)[0];
        (p, b.transpose() * p * a / s)
    }

    /// (α_j, β_j): the largest |e| and |K x| of the error ε_j that
    /// disturbances |d| ≤ w acting through ε' = (A − BK) ε + δ can build up
    /// in j steps, δ ∈ [−w h²/2, w h²/2] × [−w h, w h], by trying every
    /// sequence of the box's corners (a linear function's maximum over a
    /// box is at a corner).
    fn worst_errors(&self, w: f64, j: usize) -> (f64, f64) {
        let (_, k) = self.riccati();
        let ak = self.a() - self.b() * k;
        let corners = 4usize.pow(j as u32);
        let (mut alpha, mut beta) = (0.0f64, 0.0f64);
        for c in 0..corners {
            let mut eps = nalgebra::Vector2::zeros();
            for step in 0..j {
                let corner = (c >> (2 * step)) & 3;
                let se = if corner & 1 == 1 { 1.0 } else { -1.0 };
                let sv = if corner & 2 == 2 { 1.0 } else { -1.0 };
                let delta = nalgebra::Vector2::new(se * 0.5 * w * self.h * self.h, sv * w * self.h);
                eps = ak * eps + delta;
            }
            alpha = alpha.max(eps[0].abs());
            beta = beta.max((k * eps)[0].abs());
        }
        (alpha, beta)
    }

    /// u₀ of the QP from (e, ė) with envelope k at every step and input
    /// bound a (None: unbounded), tightened against w; None if infeasible.
    /// Also whether any inequality is active at the optimum.
    fn solve(&self, x0: [f64; 2], k: f64, a: Option<f64>, w: f64) -> Option<(f64, bool)> {
        let n = self.horizon;
        let (p, _) = self.riccati();
        let (am, bm, q) = (self.a(), self.b(), self.q());
        // x_j = Φ_j u + c_j.
        let mut phi = vec![nalgebra::DMatrix::<f64>::zeros(2, n); n + 1];
        let mut c = vec![nalgebra::Vector2::new(x0[0], x0[1]); n + 1];
        for j in 1..=n {
            phi[j] = nalgebra::DMatrix::from_column_slice(2, 2, am.as_slice()) * &phi[j - 1];
            for r in 0..2 {
                phi[j][(r, j - 1)] += bm[r];
            }
            c[j] = am * c[j - 1];
        }
        let mut hess = nalgebra::DMatrix::<f64>::identity(n, n) * self.h;
        let mut grad = nalgebra::DVector::<f64>::zeros(n);
        for j in 1..=n {
            let weight = if j == n { p } else { q };
            let wd = nalgebra::DMatrix::from_column_slice(2, 2, weight.as_slice());
            let cj = nalgebra::DVector::from_column_slice(c[j].as_slice());
            hess += phi[j].transpose() * &wd * &phi[j];
            grad += phi[j].transpose() * &wd * cj;
        }
        // Rows g_r u ≤ h_r.
        let mut rows: Vec<(nalgebra::DVector<f64>, f64)> = Vec::new();
        for j in 1..=n {
            let (alpha, _) = self.worst_errors(w, j);
            let bound = (k - alpha).max(0.0) - c[j][0];
            let g = phi[j].row(0).transpose();
            rows.push((g.clone(), bound));
            rows.push((-g, (k - alpha).max(0.0) + c[j][0]));
        }
        if let Some(a) = a {
            for i in 0..n {
                let (_, beta) = self.worst_errors(w, i);
                let mut g = nalgebra::DVector::zeros(n);
                g[i] = 1.0;
                rows.push((g.clone(), (a - beta).max(0.0)));
                rows.push((-g, (a - beta).max(0.0)));
            }
        }
        let mut best: Option<(f64, f64, bool)> = None;
        for set in subsets(rows.len(), n) {
            let m = set.len();
            let mut kkt = nalgebra::DMatrix::<f64>::zeros(n + m, n + m);
            let mut rhs = nalgebra::DVector::<f64>::zeros(n + m);
            kkt.view_mut((0, 0), (n, n)).copy_from(&hess);
            for (col, &r) in set.iter().enumerate() {
                for i in 0..n {
                    kkt[(i, n + col)] = rows[r].0[i];
                    kkt[(n + col, i)] = rows[r].0[i];
                }
                rhs[n + col] = rows[r].1;
            }
            for i in 0..n {
                rhs[i] = -grad[i];
            }
            let Some(sol) = kkt.lu().solve(&rhs) else {
                continue;
            };
            let u = sol.rows(0, n).into_owned();
            let feasible = rows.iter().all(|(g, b)| g.dot(&u) <= b + 1e-9);
            let dual_ok = (0..m).all(|i| sol[n + i] >= -1e-9);
            if feasible && dual_ok {
                let cost = 0.5 * (u.transpose() * &hess * &u)[0] + grad.dot(&u);
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, u[0], m > 0));
                }
            }
        }
        best.map(|(_, u0, active)| (u0, active))
    }
}

/// Every subset of 0 … n − 1 with at most `most` members.
fn subsets(n: usize, most: usize) -> Vec<Vec<usize>> {
    let mut out = vec![vec![]];
    for i in 0..n {
        let more: Vec<Vec<usize>> = out
            .iter()
            .filter(|s| s.len() < most)
            .map(|s| {
                let mut s = s.clone();
                s.push(i);
                s
            })
            .collect();
        out.extend(more);
    }
    out
}

/// The law's QP and the dense one at random states near a tight envelope,
/// bounded and/or tightened as `bounded`, `w` say. Returns how many states
/// had an active row in the dense solution, and how many of those the
/// nominal (unbounded, untightened) QP would have answered differently.
fn compare_with_dense(bounded: bool, w: f64, seed: u64) -> (usize, usize) {
    let (kp, kd, h, horizon, kc) = (225.0, 30.0, 0.01, 4, 0.05);
    let shape = MpcShape {
        horizon,
        h,
        tc: 0.0,
        bounded,
        disturbance: w,
    };
    let mut qp = ErrorMpc::new(&[Weights::matching(kp, kd)], shape).unwrap();
    let mut nominal_qp =
        ErrorMpc::new(&[Weights::matching(kp, kd)], nominal(horizon, h, 0.0)).unwrap();
    let dense = DenseQp { kp, kd, h, horizon };
    let mut rng = Lcg(seed);
    let (mut active, mut differs) = (0, 0);
    for _ in 0..120 {
        let sign = if rng.next() < 0.5 { -1.0 } else { 1.0 };
        let e = [sign * rng.range(0.0, 0.045)];
        let ed = [sign * rng.range(-1.0, 4.0)];
        let a = [rng.range(20.0, 200.0)];
        let (kcs, kc_dot) = ([kc], [0.0]);
        let mut x = input(1.0, &e, &ed, &kcs, &kc_dot);
        x.u_max = Some(&a);
        let want = dense.solve([e[0], ed[0]], kc, bounded.then_some(a[0]), w);
        let got = qp.solve_joint(0, &x);
        let Some((want, is_active)) = want else {
            assert!(
                got.is_none() || bounded || w > 0.0,
                "only bounds or tightening make it infeasible"
            );
            continue;
        };
        let got = got.unwrap_or_else(|| panic!("e {e:?} ė {ed:?} a {a:?}: the solver failed"));
        assert!(
            (got - want).abs() <= AGREES * want.abs().max(1.0),
            "e {e:?} ė {ed:?} a {a:?}: law {got}, dense {want}"
        );
        if is_active {
            active += 1;
            let plain = nominal_qp.solve_joint(0, &x).unwrap();
            differs += usize::from((plain - want).abs() > 1e-3 * want.abs().max(1.0));
        }
    }
    (active, differs)
}

#[test]
fn the_torque_bounded_qp_equals_a_dense_active_set_solution() {
    let (active, differs) = compare_with_dense(true, 0.0, 1);
    assert!(active >= 20, "rows active on {active} states");
    // Most active states have an envelope row active, not an input row.
    assert!(
        differs >= 5,
        "the input rows changed u₀ on {differs} states"
    );
}

#[test]
fn the_tightened_qp_equals_a_dense_active_set_solution() {
    let (active, differs) = compare_with_dense(false, 40.0, 2);
    assert!(active >= 20, "rows active on {active} states");
    assert!(
        differs >= 10,
        "the tightening changed u₀ on {differs} states"
    );
}

#[test]
fn the_bounded_tightened_qp_equals_a_dense_active_set_solution() {
    let (active, differs) = compare_with_dense(true, 40.0, 3);
    assert!(active >= 20, "rows active on {active} states");
    assert!(
        differs >= 10,
        "bounds and tightening changed u₀ on {differs} states"
    );
}

#[test]
fn the_tube_is_the_worst_disturbance_sequences_reach() {
    let (kp, kd, h, horizon, w) = (225.0, 30.0, 0.01, 6, 40.0);
    let shape = MpcShape {
        horizon,
        h,
        tc: 0.0,
        bounded: true,
        disturbance: w,
    };
    let qp = ErrorMpc::new(&[Weights::matching(kp, kd)], shape).unwrap();
    let tube = qp.tube(0);
    let dense = DenseQp { kp, kd, h, horizon };
    for j in 0..=horizon {
        let (alpha, beta) = dense.worst_errors(w, j);
        assert!(
            (tube.e[j] - alpha).abs() <= 1e-9 * alpha.max(1e-6),
            "α_{j}: {} vs {alpha}",
            tube.e[j]
        );
        if j < horizon {
            assert!(
                (tube.u[j] - beta).abs() <= 1e-9 * beta.max(1e-6),
                "β_{j}: {} vs {beta}",
                tube.u[j]
            );
        }
    }
    assert!(tube.e[horizon] > 0.0 && tube.u[horizon - 1] > 0.0);
}
