//! `mpc`'s step time on the KUKA iiwa 14 (7 joints) at 1 kHz in its worst
//! case: every joint's error near its envelope and heading out of it, so
//! that every joint's QP goes to the solver on every step (BASELINES §3).
//! One row per variant: the nominal QP without torque bounds (the
//! default), with them (the iiwa's effort limits through M(q)), the tube MPC
//! tightened against a disturbance bound, and `cbf-ctc` with torque bounds
//! and a robust margin (closed form, for scale). Prints p50, p99 and the
//! largest step time against the 1 ms period. With the iiwa's torque box
//! these states (|ė| up to 2 rad/s, at most 0.005 rad from the edge) cannot
//! be stopped inside the envelope: the bounded QPs are infeasible on every
//! step (the breach count says so), and what is timed is the solver
//! proving that.
//! `cargo bench -p launch --bench mpc_solve [-- STEPS]`.

#![allow(
    missing_docs,
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "bench code: a broken expectation should fail loudly"
)]

use std::time::Instant;

use controller::{ControllerInput, ControllerParams, Diagnostics, Law, LawName};
use plant_rapier::ArmModel;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const PERIOD_US: f64 = 1000.0;

fn main() {
    let steps: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(20_000);
    let model = ArmModel::from_urdf_str(include_str!("../../robots/iiwa14.urdf")).unwrap();
    let base = ControllerParams {
        law: LawName::Mpc,
        tc: 1e-3,
        ..ControllerParams::default()
    };
    println!(
        "iiwa14 (7 joints, every mpc QP solved; horizon {} x {} s): {steps} steps per row; period {PERIOD_US} us",
        base.mpc_horizon, base.mpc_step
    );
    let variants = [
        ("mpc (default: no torque bounds)", base.clone()),
        (
            "mpc, torque bounds",
            ControllerParams {
                torque_bounds: true,
                ..base.clone()
            },
        ),
        (
            "mpc tube, w = 20 rad/s^2",
            ControllerParams {
                mpc_disturbance: 20.0,
                ..base.clone()
            },
        ),
        (
            "cbf-ctc, bounds + margin 20",
            ControllerParams {
                law: LawName::CbfCtc,
                torque_bounds: true,
                cbf_margin: 20.0,
                ..base.clone()
            },
        ),
    ];
    for (name, params) in variants {
        time_law(name, &params, &model, steps);
    }
}

/// Steps `params`' law `steps` times at random states near a 0.01 rad
/// envelope and prints its step-time percentiles.
fn time_law(name: &str, params: &ControllerParams, model: &ArmModel, steps: usize) {
    let n = model.dof();
    let mut law = Law::new(params, n, Some(model)).unwrap();
    let mut out = Diagnostics::new(n);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let kc = vec![0.01; n];
    let (zero, kc_dot) = (vec![0.0; n], vec![0.0; n]);
    let mut times = Vec::with_capacity(steps);
    let mut breaches = 0;
    for k in 0..steps {
        let q_d: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        // e in ±(0.5, 1) k_c, ė of e's sign: the unconstrained optimum
        // leaves the envelope, so the QP is solved.
        let sign: Vec<f64> = (0..n)
            .map(|_| if rng.random_bool(0.5) { 1.0 } else { -1.0 })
            .collect();
        let q: Vec<f64> = (0..n)
            .map(|i| q_d[i] + sign[i] * rng.random_range(0.005..0.01))
            .collect();
        let qd: Vec<f64> = (0..n)
            .map(|i| sign[i] * rng.random_range(0.5..2.0))
            .collect();
        let input = ControllerInput {
            t: k as f64 * 1e-3,
            q: &q,
            qd: &qd,
            q_d: &q_d,
            qd_d: &zero,
            qdd_d: &zero,
            kc: &kc,
            kc_dot: &kc_dot,
        };
        let start = Instant::now();
        law.step(1e-3, &input, &mut out);
        times.push(start.elapsed().as_secs_f64() * 1e6);
        assert!(out.fault.is_none(), "step {k}: {:?}", out.fault);
        breaches += usize::from(out.barrier_breached);
    }
    times.sort_by(f64::total_cmp);
    let at = |p: f64| times[((p * steps as f64).ceil() as usize).clamp(1, steps) - 1];
    println!(
        "{name:30} step time: p50 {:.1} us, p99 {:.1} us, max {:.1} us; p99 / period {:.2}; breach steps {breaches}",
        at(0.5),
        at(0.99),
        times[steps - 1],
        at(0.99) / PERIOD_US
    );
}
