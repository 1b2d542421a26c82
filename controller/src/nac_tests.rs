//! Unit tests of one control step against values worked out by hand.

#![allow(
    clippy::excessive_precision,
    reason = "the expected values are quoted from 40-digit decimal arithmetic"
)]

use super::*;
use crate::{LawName, RbfLayout};
use proptest::prelude::*;

const Q: [f64; 2] = [0.3, 1.0];
const QD: [f64; 2] = [0.1, -0.2];
const Q_D: [f64; 2] = [0.2, 1.1];
const QD_D: [f64; 2] = [0.5, 0.3];
const KC: [f64; 2] = [0.5, 0.4];
const KC_DOT: [f64; 2] = [0.05, -0.02];
const QDD_D: [f64; 2] = [0.0, 0.0];

/// t = 1 s with T_c = 2 s: γ = 0.875, γ̇ = 0.375.
fn input() -> ControllerInput<'static> {
    ControllerInput {
        t: 1.0,
        q: &Q,
        qd: &QD,
        q_d: &Q_D,
        qd_d: &QD_D,
        qdd_d: &QDD_D,
        kc: &KC,
        kc_dot: &KC_DOT,
    }
}

fn step_once(params: ControllerParams, input: &ControllerInput<'_>) -> (Controller, Diagnostics) {
    let mut c = Controller::new(params, 2).unwrap();
    let mut d = c.diagnostics();
    c.step(1e-3, input, &mut d);
    (c, d)
}

fn close(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() <= tol * (1.0 + b.abs()), "{a} vs {b}");
}

// Expected values computed with 40-digit decimal arithmetic from SPEC §4–§7:
// Z1 = [0.1, −0.1], Z1γ = [0.0875, −0.0875], zero initial weights (actor term 0).
#[test]
fn per_joint_alpha_and_tau_by_hand() {
    let (_, d) = step_once(ControllerParams::default(), &input());
    assert_eq!((d.gamma, d.gamma_dot), (0.875, 0.375));
    close(d.d[0], 0.24234375, 1e-15);
    close(d.d[1], 0.15234375, 1e-15);
    close(d.alpha[0], -0.990058027079303675, 1e-14);
    close(d.alpha[1], 1.805092307692307692, 1e-14);
    close(d.z2[0], 1.090058027079303675, 1e-14);
    close(d.z2[1], -2.005092307692307692, 1e-14);
    close(d.tau[0], -16.38246292714377821, 1e-14);
    close(d.tau[1], 30.12664102564102564, 1e-14);
    assert_eq!(d.tau_actor, vec![0.0, 0.0]);
    assert!(!d.barrier_breached && d.fault.is_none());
}

#[test]
fn norm_mode_alpha_and_tau_by_hand() {
    let params = ControllerParams {
        barrier: BarrierMode::Norm,
        ..Default::default()
    };
    let (_, d) = step_once(params, &input());
    // k_c = min(0.5, 0.4) = 0.4 with k̇_c = −0.02 from joint 1.
    assert_eq!(d.kc, vec![0.4, 0.4]);
    close(d.d[0], 0.1446875, 1e-15);
    close(d.alpha[0], -1.005194384449244060, 1e-14);
    close(d.alpha[1], 1.805194384449244060, 1e-14);
    close(d.tau[0], -16.63083153347732181, 1e-14);
    close(d.tau[1], 30.13083153347732181, 1e-14);
}

#[test]
fn tau_is_the_sum_of_its_three_terms_and_actor_uses_the_weights() {
    let mut c = Controller::new(ControllerParams::default(), 2).unwrap();
    let mut d = c.diagnostics();
    c.step(1e-3, &input(), &mut d);
    // Second step: weights are now non-zero.
    let later = ControllerInput {
        t: 1.001,
        ..input()
    };
    let wa = c.actor_weights().to_vec();
    c.step(1e-3, &later, &mut d);
    let nn = c.params().neurons;
    let rbf = Rbf::new(RbfLayout::Diagonal, nn, 8, -5.0, 5.0, 1.0);
    let za: Vec<f64> = [&Q[..], &QD[..], &d.z1[..], &d.z2[..]].concat();
    let mut sa = vec![0.0; nn];
    rbf.features(&za, &mut sa);
    for j in 0..2 {
        let expected: f64 = (0..nn).map(|k| wa[j * nn + k] * sa[k]).sum();
        assert!(expected != 0.0);
        close(d.tau_actor[j], expected, 1e-12);
        close(
            d.wa_norm[j],
            wa[j * nn..(j + 1) * nn]
                .iter()
                .map(|w| w * w)
                .sum::<f64>()
                .sqrt(),
            1e-14,
        );
        assert_eq!(
            d.tau[j],
            d.tau_actor[j] + d.tau_feedback[j] + d.tau_barrier[j]
        );
        assert_eq!(d.tau_feedback[j], -15.0 * d.z2[j]);
    }
}

#[test]
fn guard_clamps_d_and_reports_a_breach() {
    // After T_c (γ = 1), joint 0 is 0.6 outside a 0.5 bound.
    let q = [0.8, 1.1];
    let inp = ControllerInput {
        t: 3.0,
        q: &q,
        ..input()
    };
    let (_, d) = step_once(ControllerParams::default(), &inp);
    assert!(d.barrier_breached);
    close(d.d[0], 0.25 - 0.36, 1e-14); // published before the clamp
    // Barrier term uses D = ε k_c²: −γ Z1γ / (β ε k_c²) = −0.6 / (10·1e-6·0.25).
    close(d.tau_barrier[0], -0.6 / (10.0 * 1e-6 * 0.25), 1e-12);
    assert!(d.tau.iter().all(|t| t.is_finite()));
    assert!(d.fault.is_none());
}

#[test]
fn non_finite_input_gives_zero_torque_and_skips_the_update() {
    let mut c = Controller::new(ControllerParams::default(), 2).unwrap();
    let mut d = c.diagnostics();
    c.step(1e-3, &input(), &mut d);
    let (wa, wc) = (c.actor_weights().to_vec(), c.critic_weights().to_vec());
    let q = [f64::NAN, 1.0];
    c.step(1e-3, &ControllerInput { q: &q, ..input() }, &mut d);
    assert_eq!(d.fault, Some(Fault::NonFiniteInput));
    assert_eq!(d.tau, vec![0.0, 0.0]);
    assert_eq!((c.actor_weights(), c.critic_weights()), (&wa[..], &wc[..]));

    let kc = [0.5, 0.0];
    c.step(1e-3, &ControllerInput { kc: &kc, ..input() }, &mut d);
    assert_eq!(d.fault, Some(Fault::EnvelopeNotPositive));
    let short = [0.1];
    c.step(
        1e-3,
        &ControllerInput {
            q: &short,
            ..input()
        },
        &mut d,
    );
    assert_eq!(d.fault, Some(Fault::WrongLength));
    // A good step afterwards works again.
    c.step(1e-3, &input(), &mut d);
    assert!(d.fault.is_none());
}

#[test]
fn first_step_uses_zero_zc_dot_and_the_critic_sees_r() {
    // With Ŵ_c = 0 and Ż_c = 0: Λ = −S_c/ψ and δ = r.
    let (c, d) = step_once(ControllerParams::default(), &input());
    let zc = [d.z1[0], d.z1[1], d.z2[0], d.z2[1]];
    let r = zc.iter().map(|z| z * z).sum::<f64>() + 0.01 * d.tau.iter().map(|t| t * t).sum::<f64>();
    close(d.r, r, 1e-14);
    assert_eq!(d.delta, d.r);
    assert_eq!((d.j_hat, d.wc_norm), (0.0, 0.0));
    // Critic moved along Λ = −S_c: Ŵ_c = exact update from 0 with s = Λ, c = r.
    let rbf = Rbf::new(RbfLayout::Diagonal, 10, 4, -5.0, 5.0, 1.0);
    let mut sc = [0.0; 10];
    rbf.features(&zc, &mut sc);
    let lambda: Vec<f64> = sc.iter().map(|s| -s).collect();
    let mut wc = [0.0; 10];
    advance_exact(&mut wc, &lambda, d.r, 50.0, 0.5, 1e-3);
    for (a, b) in c.critic_weights().iter().zip(&wc) {
        close(*a, *b, 1e-14);
    }
}

#[test]
fn euler_integrator_takes_one_euler_step() {
    let params = ControllerParams {
        integrator: Integrator::Euler,
        ..Default::default()
    };
    let (c, d) = step_once(params, &input());
    // From zero weights Euler gives Ŵ_a[:, j] = −Δt σ_a c_j S_a with c_j = Z2_j/σ_a + k_a Ĵ (Ĵ = 0).
    let za: Vec<f64> = [&Q[..], &QD[..], &d.z1[..], &d.z2[..]].concat();
    let mut sa = [0.0; 10];
    Rbf::new(RbfLayout::Diagonal, 10, 8, -5.0, 5.0, 1.0).features(&za, &mut sa);
    for j in 0..2 {
        for (k, s) in sa.iter().enumerate() {
            let expected = -1e-3 * 50.0 * (d.z2[j] / 50.0) * s;
            close(c.actor_weights()[j * 10 + k], expected, 1e-14);
        }
    }
}

#[test]
fn same_inputs_give_bit_identical_outputs() {
    let run = || {
        let mut c = Controller::new(ControllerParams::default(), 2).unwrap();
        let mut d = c.diagnostics();
        let mut out = Vec::new();
        for k in 0..50 {
            let t = 0.5 + k as f64 * 1e-3;
            c.step(1e-3, &ControllerInput { t, ..input() }, &mut d);
            out.extend(d.tau.iter().map(|x| x.to_bits()));
        }
        out
    };
    assert_eq!(run(), run());
}

proptest! {
    /// V1 is finite and non-negative while every |Z1γ_i| < k_c,i, and obeys
    /// Lemma 2: V1 < Σ Z1γ²/(β(k_c² − Z1γ²)).
    #[test]
    fn v1_finite_inside_envelope(
        k in proptest::collection::vec(0.05..2.0f64, 1..6),
        frac in proptest::collection::vec(-0.999..0.999f64, 6),
        beta in 0.1..50.0f64,
    ) {
        let z: Vec<f64> = k.iter().zip(&frac).map(|(k, f)| k * f).collect();
        let v = barrier_lyapunov(&z, &k, beta, BarrierMode::PerJoint);
        prop_assert!(v.is_finite() && v >= 0.0);
        let bound: f64 = z.iter().zip(&k).map(|(z, k)| z * z / (beta * (k * k - z * z))).sum();
        prop_assert!(v <= bound + 1e-15);
    }

    /// Inside the envelope the law is finite and the guard stays off.
    #[test]
    fn law_finite_and_unguarded_inside_envelope(
        frac in proptest::collection::vec(-0.99..0.99f64, 2),
        qd in proptest::collection::vec(-5.0..5.0f64, 2),
        t in 0.0..10.0f64,
        norm in any::<bool>(),
    ) {
        let params = ControllerParams {
            barrier: if norm { BarrierMode::Norm } else { BarrierMode::PerJoint },
            ..Default::default()
        };
        // In norm mode the whole vector must be inside the smallest bound.
        let scale = if norm { 0.4 / 2f64.sqrt() } else { 1.0 };
        let q: Vec<f64> = (0..2).map(|i| Q_D[i] + frac[i] * KC[i] * scale).collect();
        let inp = ControllerInput { t, q: &q, qd: &qd, ..input() };
        let (_, d) = step_once(params, &inp);
        prop_assert!(d.fault.is_none() && !d.barrier_breached);
        prop_assert!(d.tau.iter().all(|x| x.is_finite()));
    }
}

fn with_law(law: LawName) -> ControllerParams {
    ControllerParams {
        law,
        ..Default::default()
    }
}

// No shift (γ ≡ 1, γ̇ ≡ 0) at the same input: D = k_c² − Z1² = [0.24, 0.15],
// α = −15 Z1 + q̇_d + (k̇_c/k_c) Z1 = [−0.99, 1.805], Z2 = [1.09, −2.005],
// τ = −15 Z2 − Z1/(β D).
#[test]
fn no_shift_and_blf_by_hand() {
    let (_, d) = step_once(with_law(LawName::NacNoShift), &input());
    assert_eq!((d.gamma, d.gamma_dot), (1.0, 0.0));
    close(d.d[0], 0.24, 1e-15);
    close(d.alpha[0], -0.99, 1e-14);
    close(d.alpha[1], 1.805, 1e-14);
    close(d.tau[0], -16.35 - 0.1 / 2.4, 1e-14);
    close(d.tau[1], 30.075 + 0.1 / 1.5, 1e-14);
    // blf: β = 1, and no networks.
    let (c, d) = step_once(with_law(LawName::Blf), &input());
    close(d.tau[0], -16.35 - 0.1 / 0.24, 1e-14);
    close(d.tau[1], 30.075 + 0.1 / 0.15, 1e-14);
    assert!(c.actor_weights().iter().all(|w| *w == 0.0));
}

/// Started outside the envelope, the paper's law has γ(0) = 0 and no
/// barrier; without the shift the guard acts at once.
#[test]
fn without_the_shift_a_start_outside_the_envelope_breaches() {
    let q = [0.9, 1.0];
    let at_zero = ControllerInput {
        t: 0.0,
        q: &q,
        ..input()
    };
    let (_, d) = step_once(ControllerParams::default(), &at_zero);
    assert!(!d.barrier_breached && d.gamma == 0.0);
    let (_, d) = step_once(with_law(LawName::NacNoShift), &at_zero);
    assert!(d.barrier_breached);
    assert!(d.d[0] < 0.0 && d.tau.iter().all(|t| t.is_finite()));
    // Clamped D = ε k_c²: the barrier term is −Z1 / (β ε k_c²).
    close(d.tau_barrier[0], -0.7 / (10.0 * 1e-6 * 0.25), 1e-12);
}

#[test]
fn ablations_switch_off_their_networks() {
    let run = |law| {
        let mut c = Controller::new(with_law(law), 2).unwrap();
        let mut d = c.diagnostics();
        for k in 0..3 {
            let i = ControllerInput {
                t: 1.0 + k as f64 * 1e-3,
                ..input()
            };
            c.step(1e-3, &i, &mut d);
        }
        (c, d)
    };
    let (c, d) = run(LawName::Nac);
    assert!(c.actor_weights().iter().any(|w| *w != 0.0));
    assert!(c.critic_weights().iter().any(|w| *w != 0.0));
    assert!(d.j_hat != 0.0);
    let (c, d) = run(LawName::NacNoCritic);
    assert!(c.actor_weights().iter().any(|w| *w != 0.0));
    assert!(c.critic_weights().iter().all(|w| *w == 0.0));
    assert_eq!((d.j_hat, d.delta), (0.0, d.r));
    let (c, d) = run(LawName::NacNoNetworks);
    assert!(c.actor_weights().iter().all(|w| *w == 0.0));
    assert!(c.critic_weights().iter().all(|w| *w == 0.0));
    assert_eq!(d.tau_actor, [0.0, 0.0]);
    // Without networks the torque is the feedback and the barrier alone.
    for i in 0..2 {
        assert_eq!(d.tau[i], d.tau_feedback[i] + d.tau_barrier[i]);
    }
}

/// The per-input layout activates the actor where the diagonal one cannot.
#[test]
fn per_input_centres_make_the_actor_act() {
    let actor_after = |layout| {
        let p = ControllerParams {
            rbf_layout: layout,
            ..Default::default()
        };
        let mut c = Controller::new(p, 2).unwrap();
        let mut d = c.diagnostics();
        for k in 0..200 {
            let i = ControllerInput {
                t: 1.0 + k as f64 * 1e-3,
                ..input()
            };
            c.step(1e-3, &i, &mut d);
        }
        d.tau_actor[0].abs()
    };
    let diagonal = actor_after(RbfLayout::Diagonal);
    let per_input = actor_after(RbfLayout::PerInput);
    assert!(per_input > 100.0 * diagonal, "{per_input} vs {diagonal}");
}

#[test]
fn other_laws_are_not_built_as_the_papers() {
    assert!(Controller::new(with_law(LawName::Pd), 2).is_err());
}
