//! `pd`, `pd-gravity` and `ctc` on steps worked out by hand.

#![allow(
    clippy::unwrap_used,
    reason = "test code: a broken expectation should fail loudly"
)]

use super::*;
use crate::law_table::LawKind;
use crate::{Fault, LawName};
use arm_model::TWO_LINK_URDF;

const Q: [f64; 2] = [0.5, -0.5];
const QD: [f64; 2] = [1.0, -1.0];
const Q_D: [f64; 2] = [0.2, 0.1];
const QD_D: [f64; 2] = [0.5, 0.5];
const QDD_D: [f64; 2] = [2.0, -1.0];
const KC: [f64; 2] = [0.5, 0.5];

fn input() -> ControllerInput<'static> {
    ControllerInput {
        t: 1.0,
        q: &Q,
        qd: &QD,
        q_d: &Q_D,
        qd_d: &QD_D,
        qdd_d: &QDD_D,
        kc: &KC,
        kc_dot: &[0.0, 0.0],
    }
}

/// The feedback law `p.law` names.
fn new_feedback(
    p: &ControllerParams,
    dof: usize,
    model: Option<&ArmModel>,
) -> Result<Feedback, ControllerError> {
    let LawKind::Feedback(kind) = p.law.kind() else {
        panic!("{} is not a feedback law", p.law)
    };
    Feedback::new(p, kind, dof, model)
}

fn params(law: LawName) -> ControllerParams {
    ControllerParams {
        law,
        k1: crate::Gain::Each(vec![2.0, 4.0]),
        k2: crate::Gain::All(3.0),
        ..Default::default()
    }
}

fn step(law: LawName, model: Option<&ArmModel>) -> Diagnostics {
    let mut f = new_feedback(&params(law), 2, model).unwrap();
    let mut d = Diagnostics::new(2);
    f.step(&input(), &mut d);
    d
}

// e = [0.3, −0.6], ė = [0.5, −1.5]; K_p = K1 K2 = [6, 12], K_d = K2 = 3.
#[test]
fn pd_by_hand_both_signs() {
    let d = step(LawName::Pd, None);
    assert!((d.tau[0] - (-1.8 - 1.5)).abs() < 1e-15);
    assert!((d.tau[1] - (7.2 + 4.5)).abs() < 1e-15);
    assert_eq!(d.z1, [0.3, -0.6]);
    assert_eq!(d.z2, [0.5, -1.5]);
    assert_eq!(d.tau_model, [0.0, 0.0]);
    assert!(d.fault.is_none() && !d.barrier_breached);
}

#[test]
fn pd_gravity_adds_the_models_gravity() {
    let model = ArmModel::from_urdf_str(TWO_LINK_URDF).unwrap();
    let d = step(LawName::PdGravity, Some(&model));
    let g = Dynamics::new(&model, 1.0).gravity(&Q).to_vec();
    assert_eq!(d.tau_model, g);
    assert!((d.tau[0] - (g[0] - 3.3)).abs() < 1e-12);
    assert!((d.tau[1] - (g[1] + 11.7)).abs() < 1e-12);
}

// v = q̈_d − (K1 + K2) ė − K1 K2 e = [2 − 2.5 − 1.8, −1 + 10.5 + 7.2].
#[test]
fn ctc_is_the_models_inverse_dynamics_at_the_commanded_acceleration() {
    let model = ArmModel::from_urdf_str(TWO_LINK_URDF).unwrap();
    let d = step(LawName::Ctc, Some(&model));
    let want = Dynamics::new(&model, 1.0)
        .inverse(&Q, &QD, &[2.0 - 2.5 - 1.8, -1.0 + 10.5 + 7.2])
        .to_vec();
    for i in 0..2 {
        assert!(
            (d.tau[i] - want[i]).abs() < 1e-12,
            "{:?} vs {want:?}",
            d.tau
        );
    }
    // A model 20 % light scales every term of the torque by 0.8.
    let light = ControllerParams {
        model_scale: 0.8,
        ..params(LawName::Ctc)
    };
    let mut f = new_feedback(&light, 2, Some(&model)).unwrap();
    let mut d8 = Diagnostics::new(2);
    f.step(&input(), &mut d8);
    for (a, b) in d8.tau.iter().zip(&want) {
        assert!((a - 0.8 * b).abs() < 1e-12);
    }
}

#[test]
fn a_model_based_law_without_a_model_is_refused() {
    let e = new_feedback(&params(LawName::Ctc), 2, None).unwrap_err();
    assert_eq!(e, ControllerError::NeedsModel(LawName::Ctc));
    assert!(e.to_string().contains("'ctc' is model-based"));
}

#[test]
fn a_non_finite_input_gives_zero_torque_and_a_fault() {
    let mut f = new_feedback(&params(LawName::Pd), 2, None).unwrap();
    let mut d = Diagnostics::new(2);
    let q = [f64::NAN, 0.0];
    f.step(&ControllerInput { q: &q, ..input() }, &mut d);
    assert_eq!(d.fault, Some(Fault::NonFiniteInput));
    assert_eq!(d.tau, [0.0, 0.0]);
}

/// BASELINES.md §6: on one joint M is a number m, so matched `ctc`
/// (K_p' = K1 K2 / m, K_d' = K2 / m) at q̈_d = 0 is `pd-gravity` exactly;
/// as given it is not.
#[test]
fn matched_ctc_on_one_joint_is_pd_with_gravity() {
    let locks = arm_model::Locks::from([("joint2".to_string(), 0.4)]);
    let model = ArmModel::from_urdf_str_locked(TWO_LINK_URDF, &locks).unwrap();
    let one = |law: LawName, tuning: Tuning| {
        let p = ControllerParams {
            law,
            k1: 2.0.into(),
            k2: 3.0.into(),
            tuning,
            ..Default::default()
        };
        let mut f = new_feedback(&p, 1, Some(&model)).unwrap();
        let mut d = Diagnostics::new(1);
        f.step(
            &ControllerInput {
                t: 0.0,
                q: &[0.5],
                qd: &[1.0],
                q_d: &[0.2],
                qd_d: &[0.5],
                qdd_d: &[0.0],
                kc: &[0.5],
                kc_dot: &[0.0],
            },
            &mut d,
        );
        d.tau[0]
    };
    let pd_g = one(LawName::PdGravity, Tuning::AsGiven);
    let matched = one(LawName::Ctc, Tuning::Matched);
    assert!(
        (matched - pd_g).abs() < 1e-9 * pd_g.abs(),
        "{matched} vs {pd_g}"
    );
    assert!((one(LawName::Ctc, Tuning::AsGiven) - pd_g).abs() > 0.1);
}

// s = ė + K1 e = [0.5 + 2·0.3, −1.5 + 4·(−0.6)] = [1.1, −3.9], both past
// the boundary layer (φ = 0.05): τ = −K2 s − k_s sign(s) = [−3.3 − 2, 11.7 + 2].
#[test]
fn smc_by_hand_outside_the_boundary_layer() {
    let d = step(LawName::Smc, None);
    assert!((d.tau[0] - (-5.3)).abs() < 1e-12, "{:?}", d.tau);
    assert!((d.tau[1] - 13.7).abs() < 1e-12, "{:?}", d.tau);
    assert!((d.z2[0] - 1.1).abs() < 1e-12 && (d.z2[1] + 3.9).abs() < 1e-12);
    assert_eq!(d.tau_model, vec![0.0, 0.0]);
}

// Inside the layer the switch is linear: s = 0.02 → k_s s / φ = 2 · 0.4.
#[test]
fn smc_by_hand_inside_the_boundary_layer() {
    let mut f = new_feedback(&params(LawName::Smc), 2, None).unwrap();
    let mut d = Diagnostics::new(2);
    // e = 0.01, ė = 0: s = K1 e = [0.02, 0.04].
    let q = [Q_D[0] + 0.01, Q_D[1] + 0.01];
    let input = ControllerInput {
        q: &q,
        qd: &QD_D,
        ..input()
    };
    f.step(&input, &mut d);
    let want = [-3.0 * 0.02 - 2.0 * 0.4, -3.0 * 0.04 - 2.0 * 0.8];
    for i in 0..2 {
        assert!(
            (d.tau[i] - want[i]).abs() < 1e-12,
            "{:?} vs {want:?}",
            d.tau
        );
    }
}

// cbf-ctc from T_c on (T_c = 0.5, t = 1), λ = 20, k_c = 0.5, k̇_c = 0;
// ctc's as-given gains K_p' = K1 K2 = [6, 12], K_d' = K1 + K2 = [5, 7].
// Joint 1: e = 0.3 inside: u_nom = −5·0.5 − 6·0.3 = −4.3, bound
// b/(2e) = (−0.5 − 12 + 64)/0.6 = 85.83: the filter leaves it.
// Joint 2: e = −0.6 outside: u_nom = 10.5 + 7.2 = 17.7, b = −4.5 − 72 − 44
// = −120.5, bound −120.5/−1.2 = 100.4167 > u_nom: u is raised to it.
#[test]
fn cbf_ctc_by_hand_filters_only_the_joint_that_needs_it() {
    let model = ArmModel::from_urdf_str(TWO_LINK_URDF).unwrap();
    let p = ControllerParams {
        tc: 0.5,
        ..params(LawName::CbfCtc)
    };
    let mut f = new_feedback(&p, 2, Some(&model)).unwrap();
    let mut d = Diagnostics::new(2);
    f.step(&input(), &mut d);
    let v = [QDD_D[0] - 4.3, QDD_D[1] + 120.5 / 1.2];
    let want = Dynamics::new(&model, 1.0).inverse(&Q, &QD, &v).to_vec();
    for i in 0..2 {
        assert!((d.tau[i] - want[i]).abs() < 1e-9, "{:?} vs {want:?}", d.tau);
    }
    assert!(
        d.barrier_breached,
        "the filter clipped joint 2: a breach step"
    );
    // Before T_c it is ctc.
    let mut ctc = new_feedback(&params(LawName::Ctc), 2, Some(&model)).unwrap();
    let mut cbf = new_feedback(&params(LawName::CbfCtc), 2, Some(&model)).unwrap();
    let (mut a, mut b) = (Diagnostics::new(2), Diagnostics::new(2));
    ctc.step(&input(), &mut a);
    cbf.step(&input(), &mut b);
    assert_eq!(a.tau, b.tau);
}
