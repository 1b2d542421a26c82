#![allow(clippy::unwrap_used)]
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
    }
}

#[test]
fn its_unconstrained_gain_has_ctcs_poles_as_the_step_shrinks() {
    // s² + 30 s + 225: K_p = 225, K_d = 30, the default gains' ctc.
    for (h, tol) in [(0.01, 0.15), (0.001, 0.02)] {
        let qp = ErrorMpc::new(&[Weights::matching(225.0, 30.0)], 20, h, 0.0).unwrap();
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
    let mut qp = ErrorMpc::new(&w, 20, 0.01, 10.0).unwrap();
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
            (solved - want).abs() <= 1e-6 * want.abs().max(1.0),
            "{i}: {solved} vs {want}"
        );
    }
}

#[test]
fn an_active_envelope_bends_the_input() {
    let w = [Weights::matching(225.0, 30.0)];
    let mut qp = ErrorMpc::new(&w, 20, 0.01, 0.0).unwrap();
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
