//! The environment's core against `testbed sim` (bit for bit), and its
//! reward, ends, options, vector form and picture.

// Reason: a test's helpers stop it with a message, as the tests do.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use gym_env::{ActionMode, ArmEnv, ArmEnvs, ERROR_CAP, EnvError, EnvOptions, Outcome};
use scenario::{Overrides, Plan};

/// The paper's scenario, `duration` s long, with `set` applied.
fn plan(duration: f64, set: &[&str]) -> Plan {
    let overrides = Overrides {
        duration_s: Some(duration),
        set: set
            .iter()
            .map(|s| scenario::parse_set(s).expect("a valid --set"))
            .collect(),
        ..Default::default()
    };
    scenario::load_named(None, &overrides).expect("the paper's scenario loads")
}

/// The states (q) and torques of `testbed sim` on `plan`, one per step.
fn sim_rows(plan: &Plan) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let (mut q, mut tau) = (Vec::new(), Vec::new());
    run_stack::sim::run(plan, |r| {
        q.push(r.q.to_vec());
        tau.push(r.tau.to_vec());
        Ok(())
    })
    .expect("sim runs");
    (q, tau)
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn residual_on_own_law(plan: &Plan, decimation: u32) -> EnvOptions {
    EnvOptions {
        action: ActionMode::Residual(plan.scenario.controller.law),
        decimation,
        ..EnvOptions::default()
    }
}

#[test]
fn a_zero_residual_equals_sim_bit_for_bit() {
    let p = plan(0.3, &[]);
    let (sim_q, sim_tau) = sim_rows(&p);
    let mut env = ArmEnv::new(p.clone(), residual_on_own_law(&p, 1)).expect("env");
    let n = env.dof();
    let mut obs = vec![0.0; env.obs_dim()];
    env.reset(p.scenario.seed, &mut obs).expect("reset");
    assert_eq!(bits(&env.state().q[..n]), bits(&sim_q[0]));
    for k in 0..sim_q.len() {
        let out = env.step(&vec![0.0; n], &mut obs);
        assert_eq!(
            bits(env.last_torque()),
            bits(&sim_tau[k]),
            "torque of step {k}"
        );
        if k + 1 < sim_q.len() {
            assert_eq!(
                bits(&env.state().q[..n]),
                bits(&sim_q[k + 1]),
                "state {}",
                k + 1
            );
        }
        assert_eq!(out.truncated, k + 1 == sim_q.len());
    }
}

#[test]
fn a_zero_residual_held_over_decimation_equals_sim_bit_for_bit() {
    let p = plan(0.3, &[]);
    let (sim_q, _) = sim_rows(&p);
    let mut env = ArmEnv::new(p.clone(), residual_on_own_law(&p, 20)).expect("env");
    let n = env.dof();
    let mut obs = vec![0.0; env.obs_dim()];
    env.reset(p.scenario.seed, &mut obs).expect("reset");
    assert_eq!(env.decisions(), 15);
    for j in 1..15 {
        env.step(&vec![0.0; n], &mut obs);
        assert_eq!(env.step_index(), 20 * j as u64);
        assert_eq!(
            bits(&env.state().q[..n]),
            bits(&sim_q[20 * j]),
            "decision {j}"
        );
    }
}

#[test]
fn the_reward_is_the_error_over_the_envelope_and_the_effort() {
    let p = plan(0.3, &[]);
    let opts = EnvOptions {
        decimation: 1,
        effort_weight: 0.5,
        ..EnvOptions::default()
    };
    let mut env = ArmEnv::new(p, opts).expect("env");
    let n = env.dof();
    let mut obs = vec![0.0; env.obs_dim()];
    env.reset(3, &mut obs).expect("reset");
    let a = [0.5, -2.0]; // the second is clipped to -1
    let out = env.step(&a[..n], &mut obs);
    let (s, r) = (env.state(), env.reference());
    let mut err = 0.0;
    for i in 0..n {
        let e = (s.q[i] - r.q_d[i]).abs() / r.kc[i];
        err += (e * e).min(ERROR_CAP);
    }
    let effort = 0.5 * (0.25 + 1.0) / n as f64;
    let want = -err / n as f64 - effort;
    assert!(
        (out.reward - want).abs() < 1e-12,
        "{} vs {want}",
        out.reward
    );
    assert_eq!(out.cost, 0.0, "no cost before T_c");
    // The torque is the clipped action times the scale.
    assert_eq!(env.last_torque()[1], -env.scale()[1]);
    // The observation's first entries are e / k_c of the measured state.
    let e0 = (s.q_measured[0] - r.q_d[0]) / r.kc[0];
    assert_eq!(obs[0].to_bits(), e0.to_bits());
}

#[test]
fn an_episode_ends_truncated_at_its_last_decision_even_a_short_one() {
    let p = plan(0.1, &[]);
    let opts = EnvOptions {
        decimation: 30,
        ..EnvOptions::default()
    };
    let mut env = ArmEnv::new(p, opts).expect("env");
    let mut obs = vec![0.0; env.obs_dim()];
    env.reset(1, &mut obs).expect("reset");
    assert_eq!(env.decisions(), 4);
    let zero = vec![0.0; env.dof()];
    for j in 0..3 {
        let out = env.step(&zero, &mut obs);
        assert!(!out.truncated && !out.terminated, "decision {j}");
    }
    let out = env.step(&zero, &mut obs);
    assert!(out.truncated && !out.terminated);
    assert_eq!(env.step_index(), 100);
    assert_eq!(obs[obs.len() - 1], 1.0, "the time fraction ends at 1");
}

/// A torque that throws the arm out of its envelope soon after T_c.
fn breaching(safe: bool) -> (ArmEnv, Vec<Outcome>) {
    let p = plan(1.0, &["controller.tc=0.1"]);
    let opts = EnvOptions {
        decimation: 10,
        torque_scale: Some(vec![200.0; p.robot.model.dof()]),
        safe,
        ..EnvOptions::default()
    };
    let mut env = ArmEnv::new(p, opts).expect("env");
    let mut obs = vec![0.0; env.obs_dim()];
    env.reset(2, &mut obs).expect("reset");
    let push = vec![1.0; env.dof()];
    let mut outs = Vec::new();
    loop {
        let o = env.step(&push, &mut obs);
        outs.push(o);
        if o.terminated || o.truncated {
            return (env, outs);
        }
    }
}

#[test]
fn a_breach_ends_the_episode_and_is_charged_every_step_it_skips() {
    let (env, outs) = breaching(false);
    let last = outs.last().copied().unwrap_or_default();
    assert!(last.terminated && !last.truncated);
    assert_eq!(last.cost, 1.0);
    let skipped = env.decisions() - outs.len() as u64;
    assert!(skipped > 0, "the breach comes before the end");
    let worst = -(ERROR_CAP + env.options().effort_weight);
    // The early end costs at least the worst reward of every skipped step:
    // staying in the worst state would not have been charged more.
    assert!(last.reward <= worst * skipped as f64, "{}", last.reward);
}

#[test]
fn safe_mode_never_ends_early_and_keeps_reward_and_cost_apart() {
    let (env, outs) = breaching(true);
    assert_eq!(outs.len() as u64, env.decisions());
    assert!(outs.iter().all(|o| !o.terminated));
    assert!(outs.last().is_some_and(|o| o.truncated));
    let costly: Vec<_> = outs.iter().filter(|o| o.cost == 1.0).collect();
    assert!(!costly.is_empty(), "the breach is a cost");
    // The reward is never charged for the cost: no step's reward is below
    // the worst a step can have.
    let worst = -(ERROR_CAP + env.options().effort_weight);
    assert!(outs.iter().all(|o| o.reward >= worst - 1e-12));
}

#[test]
fn the_vector_form_is_the_single_env_row_by_row_and_resets_itself() {
    let p = plan(0.1, &[]);
    let opts = EnvOptions {
        decimation: 25,
        ..EnvOptions::default()
    };
    let mut envs = ArmEnvs::new(p.clone(), opts.clone(), 3).expect("envs");
    let d = envs.obs_dim();
    let n = envs.envs()[0].dof();
    let mut obs = vec![0.0; 3 * d];
    envs.reset(40, &mut obs).expect("reset");
    let actions: Vec<f64> = (0..3 * n).map(|i| 0.1 * i as f64 - 0.2).collect();
    let mut out = vec![Outcome::default(); 3];
    let mut rows = vec![Vec::new(); 3];
    for _ in 0..4 {
        envs.step(&actions, &mut obs, &mut out).expect("step");
        for i in 0..3 {
            rows[i].push((bits(&obs[i * d..(i + 1) * d]), out[i]));
        }
    }
    for i in 0..3 {
        let mut one = ArmEnv::new(p.clone(), opts.clone()).expect("env");
        let mut o = vec![0.0; d];
        one.reset(40 + i as u64, &mut o).expect("reset");
        for (j, (row, outcome)) in rows[i].iter().enumerate() {
            let got = one.step(&actions[i * n..(i + 1) * n], &mut o);
            assert_eq!(&bits(&o), row, "arm {i}, step {j}");
            assert_eq!(&got, outcome);
        }
        assert!(rows[i][3].1.truncated);
    }
    // The step after the end resets: reward 0, a fresh first observation.
    envs.step(&actions, &mut obs, &mut out).expect("step");
    assert!(out.iter().all(|o| *o == Outcome::default()));
    assert_eq!(obs[d - 1], 0.0, "a new episode's time fraction");
    assert!(envs.envs().iter().all(|e| e.step_index() == 0));
}

#[test]
fn vector_seeds_past_the_last_u64_are_refused_not_wrapped() {
    let mut envs = ArmEnvs::new(plan(0.1, &[]), EnvOptions::default(), 2).expect("envs");
    let mut obs = vec![0.0; 2 * envs.obs_dim()];
    let e = envs.reset(u64::MAX, &mut obs).err();
    assert!(
        matches!(e, Some(EnvError::Option { ref name, .. }) if name == "seed"),
        "{e:?}"
    );
    envs.reset(u64::MAX - 1, &mut obs)
        .expect("the last seed that fits");
}

#[test]
fn a_bad_option_is_named_with_its_value() {
    let p = plan(0.1, &[]);
    for (opts, name) in [
        (
            EnvOptions {
                decimation: 0,
                ..EnvOptions::default()
            },
            "decimation",
        ),
        (
            EnvOptions {
                residual_scale: f64::NAN,
                ..EnvOptions::default()
            },
            "residual_scale",
        ),
        (
            EnvOptions {
                effort_weight: 1.7e308,
                ..EnvOptions::default()
            },
            "effort_weight",
        ),
        (
            EnvOptions {
                breach_factor: Some(0.5),
                ..EnvOptions::default()
            },
            "breach_factor",
        ),
        (
            EnvOptions {
                torque_scale: Some(vec![1.0]),
                ..EnvOptions::default()
            },
            "torque_scale",
        ),
        (
            EnvOptions {
                torque_scale: Some(vec![1.0, -1.0]),
                ..EnvOptions::default()
            },
            "torque_scale[1]",
        ),
    ] {
        match ArmEnv::new(p.clone(), opts) {
            Err(EnvError::Option { name: got, .. }) => assert_eq!(got, name),
            Err(e) => panic!("{name}: another error: {e}"),
            Ok(_) => panic!("{name}: accepted"),
        }
    }
    assert!(gym_env::check_episode_s(0.0).is_err());
    assert!(gym_env::check_episode_s(f64::NAN).is_err());
    assert_eq!(gym_env::check_episode_s(4.0).ok(), Some(4.0));
}

#[test]
fn the_derived_torque_scale_follows_its_rule() {
    let p = plan(4.0, &[]);
    let env = ArmEnv::new(p.clone(), EnvOptions::default()).expect("env");
    let m = &p.robot.model;
    let mut dynamics = arm_model::dynamics::Dynamics::new(m, p.scenario.plant.mass_scale);
    let mut r = trajectory::ReferenceSample::new(m.dof());
    p.reference.sample_into(0.0, &mut r);
    let g0 = dynamics.gravity(&r.q_d).to_vec();
    for (i, &j) in m.actuated.iter().enumerate() {
        let limit = m.joints[j].effort.unwrap_or(f64::INFINITY);
        let s = env.scale()[i];
        assert!(
            s <= limit && s >= 0.1 * limit,
            "joint {i}: {s} against the limit {limit}"
        );
        assert!(
            s >= (2.0 * g0[i].abs()).min(limit),
            "joint {i}: {s} under 2 G = {}",
            g0[i]
        );
    }
    // A scenario's own effort limit is the one the rule reads.
    let capped = plan(4.0, &["plant.effort_limit=30.0"]);
    let env = ArmEnv::new(capped, EnvOptions::default()).expect("env");
    assert!(
        env.scale().iter().all(|&s| (3.0..=30.0).contains(&s)),
        "{:?}",
        env.scale()
    );
}

#[test]
fn reset_options_set_the_start_and_are_checked_by_name() {
    let mut env = ArmEnv::new(plan(0.1, &[]), EnvOptions::default()).expect("env");
    let n = env.dof();
    let mut obs = vec![0.0; env.obs_dim()];
    let start = gym_env::ResetOptions {
        initial_q: Some(vec![0.25; n]),
        initial_qd: None,
    };
    let plain = env.plan().scenario.initial.q.clone();
    env.reset_with(5, &start, &mut obs).expect("reset");
    assert_eq!(&env.state().q[..n], &vec![0.25; n][..]);
    // The options hold for that episode only: a plain reset starts where
    // the scenario says.
    env.reset(5, &mut obs).expect("reset");
    assert_eq!(&env.state().q[..n], &plain[..]);
    let bad = gym_env::ResetOptions {
        initial_q: None,
        initial_qd: Some(vec![0.0; n + 1]),
    };
    let e = env.reset_with(5, &bad, &mut obs).err();
    assert!(
        matches!(e, Some(EnvError::Option { ref name, .. }) if name == "initial_qd"),
        "{e:?}"
    );
}

#[test]
fn the_picture_shows_the_arm_and_moves_with_it() {
    let mut env = ArmEnv::new(plan(0.5, &[]), EnvOptions::default()).expect("env");
    let mut obs = vec![0.0; env.obs_dim()];
    env.reset(0, &mut obs).expect("reset");
    let first = env.render(120, 90).expect("a picture");
    assert_eq!(first.len(), 120 * 90 * 3);
    let dark = |px: &[u8]| px.chunks(3).filter(|c| c == &[40, 40, 40]).count();
    assert!(dark(&first) > 50, "the arm is drawn");
    let push = vec![1.0; env.dof()];
    for _ in 0..10 {
        env.step(&push, &mut obs);
    }
    let later = env.render(120, 90).expect("a picture");
    assert_ne!(first, later, "the arm moved");
    assert!(env.render(4, 90).is_err(), "a picture too small is refused");
}

/// #59 item 1: a reset forgets the last episode's ramp and last action,
/// so an episode is the same however many came before it; a bad low-pass
/// built in Rust is refused as Python's is.
#[test]
fn a_smoothed_episode_is_the_same_after_another_and_a_bad_low_pass_is_refused() {
    let p = plan(0.3, &[]);
    let opts = EnvOptions {
        action: ActionMode::Residual(p.scenario.controller.law),
        smoothing: gym_env::Smoothing::Ramp,
        observe_action: true,
        decimation: 7,
        ..EnvOptions::default()
    };
    let mut env = ArmEnv::new(p.clone(), opts.clone()).unwrap();
    let mut obs = vec![0.0; env.obs_dim()];
    let mut episode = |env: &mut ArmEnv| {
        env.reset(3, &mut obs).unwrap();
        let mut out = bits(&obs);
        for k in 0..env.decisions() {
            let a = [(k as f64 * 0.7).sin(), (k as f64 * 1.3).cos()];
            env.step(&a, &mut obs);
            out.extend(bits(&obs));
        }
        out
    };
    let first = episode(&mut env);
    // 300 periods at 7 a decision: the last decision is 6 periods long.
    assert_eq!(env.decisions(), 43);
    assert_eq!(episode(&mut env), first);
    for tau_s in [0.0, -1.0, f64::NAN] {
        let bad = EnvOptions {
            smoothing: gym_env::Smoothing::LowPass { tau_s },
            ..opts.clone()
        };
        match ArmEnv::new(p.clone(), bad) {
            Err(EnvError::Option { name, .. }) => assert_eq!(name, "smoothing_tau_s"),
            other => panic!("τ = {tau_s}: {:?}", other.map(|_| ())),
        }
    }
}
