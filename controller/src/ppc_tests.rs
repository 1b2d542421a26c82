//! The funnel law on steps worked out by hand.

#![allow(
    clippy::unwrap_used,
    reason = "test code: a broken expectation should fail loudly"
)]

use super::*;
use crate::LawName;

fn params() -> ControllerParams {
    ControllerParams {
        law: LawName::Ppc,
        k1: 2.0.into(),
        k2: 3.0.into(),
        tc: 1.0,
        rho2_inf: 2.0,
        ..Default::default()
    }
}

fn input<'a>(t: f64, q: &'a [f64], qd: &'a [f64], kc: &'a [f64]) -> ControllerInput<'a> {
    ControllerInput {
        t,
        q,
        qd,
        q_d: &[0.0],
        qd_d: &[0.0],
        qdd_d: &[0.0],
        kc,
        kc_dot: &[0.0],
    }
}

fn eps(xi: f64) -> f64 {
    ((1.0 + xi) / (1.0 - xi)).ln()
}

// t = 0: ρ1 = ρ1,0 = |e| + k_c = 0.4, ξ1 = 0.75, α = −2 ln 7, Z2 = 2 ln 7,
// ρ2 = 2 Z2 + 2, τ = −3 ε(Z2 / ρ2).
#[test]
fn first_step_by_hand_and_the_sign_follows_the_error() {
    let mut p = Ppc::new(&params(), 1).unwrap();
    let mut d = Diagnostics::new(1);
    p.step(&input(0.0, &[0.3], &[0.0], &[0.1]), &mut d);
    let z2 = 2.0 * 7f64.ln();
    assert!((d.kc[0] - 0.4).abs() < 1e-15);
    assert!((d.alpha[0] + z2).abs() < 1e-14);
    let tau = -3.0 * eps(z2 / (2.0 * z2 + 2.0));
    assert!((d.tau[0] - tau).abs() < 1e-14, "{} vs {tau}", d.tau[0]);
    assert!(d.tau[0] < 0.0 && !d.barrier_breached);
    let mut p = Ppc::new(&params(), 1).unwrap();
    p.step(&input(0.0, &[-0.3], &[0.0], &[0.1]), &mut d);
    assert!((d.tau[0] + tau).abs() < 1e-14);
}

// At t = 0.5 the funnel is (0.4 − 0.1) e^{−1.5} + 0.1 = 0.167: an error of
// −0.2 is outside it, ξ1 is clamped and the step counts as a breach.
#[test]
fn outside_the_funnel_xi_is_clamped_and_a_breach_counted() {
    let mut p = Ppc::new(&params(), 1).unwrap();
    let mut d = Diagnostics::new(1);
    p.step(&input(0.0, &[0.3], &[0.0], &[0.1]), &mut d);
    p.step(&input(0.5, &[-0.2], &[0.0], &[0.1]), &mut d);
    let rho1 = 0.3 * (-1.5f64).exp() + 0.1;
    assert!((d.kc[0] - rho1).abs() < 1e-15);
    assert!(d.barrier_breached);
    assert!(d.tau[0].is_finite() && d.tau[0] > 0.0);
    assert!((d.alpha[0] - 2.0 * eps(1.0 - XI_LIMIT)).abs() < 1e-9);
    // Just inside the position funnel ξ1 is not clamped.
    p.step(&input(0.5, &[-0.99 * rho1], &[0.0], &[0.1]), &mut d);
    assert!((d.alpha[0] + 2.0 * eps(-0.99)).abs() < 1e-9);
}

#[test]
fn a_non_finite_input_gives_zero_torque_and_a_fault() {
    let mut p = Ppc::new(&params(), 1).unwrap();
    let mut d = Diagnostics::new(1);
    p.step(&input(0.0, &[f64::INFINITY], &[0.0], &[0.1]), &mut d);
    assert_eq!(d.fault, Some(crate::Fault::NonFiniteInput));
    assert_eq!(d.tau, [0.0]);
}

/// BASELINES.md §6: matched, the funnel law near e = 0 with its funnels
/// at their final widths is `pd` with the same K1, K2.
#[test]
fn matched_tuning_is_pd_near_zero_error() {
    let matched = ControllerParams {
        tuning: crate::Tuning::Matched,
        ..params()
    };
    let mut p = Ppc::new(&matched, 1).unwrap();
    let kc = [0.3];
    let mut out = Diagnostics::new(1);
    p.step(&input(0.0, &[0.0], &[0.0], &kc), &mut out);
    let (e, ed) = (1e-5, 3e-5);
    p.step(&input(100.0, &[e], &[ed], &kc), &mut out);
    let pd = -3.0 * (ed + 2.0 * e);
    assert!(
        (out.tau[0] - pd).abs() < 1e-6 * pd.abs(),
        "{} vs {pd}",
        out.tau[0]
    );
    // As given, the same step is a far stiffer pd (K1_eff = 2 k1 / k_c).
    let mut q = Ppc::new(&params(), 1).unwrap();
    q.step(&input(0.0, &[0.0], &[0.0], &kc), &mut out);
    q.step(&input(100.0, &[e], &[ed], &kc), &mut out);
    assert!((out.tau[0] - pd).abs() > 0.5 * pd.abs());
}
