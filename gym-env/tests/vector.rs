//! The vector form on a pool of threads: the same bits as on one thread,
//! and Stable-Baselines3's same-step autoreset as Gymnasium's next-step
//! one with the reset steps taken out.

// Reason: a test's helpers stop it with a message, as the tests do.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use std::path::Path;

use gym_env::{ArmEnvs, Autoreset, EnvError, EnvOptions, Outcome, ResetOptions};
use scenario::{Overrides, Plan};

/// A randomised scenario (every seed draws another start), episodes of
/// 0.1 s with a decision every 10 ms: ten decisions an episode.
fn plan() -> Plan {
    let overrides = Overrides {
        duration_s: Some(0.1),
        // The constraint from 20 ms on, so that breaches end episodes.
        set: vec![scenario::parse_set("controller.tc=0.02").expect("a valid --set")],
        ..Default::default()
    };
    scenario::load_named(Some(Path::new("paper_randomised")), &overrides).expect("loads")
}

fn opts() -> EnvOptions {
    EnvOptions {
        decimation: 10,
        // Ends early too (a breach after T_c), not only at the time limit.
        breach_factor: Some(1.5),
        ..EnvOptions::default()
    }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A policy of the observation alone (so that arms whose steps fall
/// differently still act the same in the same state), strong enough to
/// breach now and then.
fn act(obs: &[f64], d: usize, n: usize) -> Vec<f64> {
    obs.chunks(d)
        .flat_map(|o| (0..n).map(move |j| 0.5 * (3.0 * o[j] - 0.7 * o[n + j] + 0.3).sin()))
        .collect()
}

type Trace = Vec<(Vec<u64>, Vec<Outcome>, Vec<u64>)>;

/// `steps` steps of `count` arms on `threads` threads in `mode`: each
/// step's observations, outcomes and final observations (bits).
fn trace(count: usize, threads: usize, mode: Autoreset, steps: usize) -> Trace {
    let mut envs = ArmEnvs::with_threads(plan(), opts(), count, threads).expect("envs");
    assert_eq!(envs.threads(), threads.min(count));
    let (d, n) = (envs.obs_dim(), envs.envs()[0].dof());
    let mut obs = vec![0.0; count * d];
    let mut fin = vec![f64::NAN; count * d];
    let mut out = vec![Outcome::default(); count];
    envs.reset(11, &mut obs).expect("reset");
    let mut rows = Vec::new();
    for _ in 0..steps {
        let a = act(&obs, d, n);
        envs.step_with(mode, &a, &mut obs, Some(&mut fin), &mut out)
            .expect("step");
        rows.push((bits(&obs), out.clone(), bits(&fin)));
    }
    rows
}

#[test]
fn threads_give_the_bits_of_one_thread_in_both_autoreset_modes() {
    for mode in [Autoreset::NextStep, Autoreset::SameStep] {
        let one = trace(7, 1, mode, 35);
        // Both kinds of end happened, or the test would not test resets.
        let ends = |f: fn(&Outcome) -> bool| one.iter().flat_map(|r| &r.1).filter(|o| f(o)).count();
        assert!(ends(|o| o.terminated) > 0, "{mode:?}: no breach");
        assert!(ends(|o| o.truncated) > 0, "{mode:?}: no time limit");
        for threads in [2, 3, 16] {
            let many = trace(7, threads, mode, 35);
            for (k, (a, b)) in one.iter().zip(&many).enumerate() {
                assert_eq!(a, b, "{mode:?}, {threads} threads, step {k}");
            }
        }
    }
}

#[test]
fn same_step_autoreset_is_next_step_without_its_reset_steps() {
    let (count, steps) = (5, 40);
    let next = trace(count, 2, Autoreset::NextStep, steps);
    let same = trace(count, 2, Autoreset::SameStep, steps + 10);
    let d = next[0].0.len() / count;
    for i in 0..count {
        let row = |r: &Vec<u64>| r[i * d..(i + 1) * d].to_vec();
        // NEXT_STEP: a step after an end is a reset (outcome all zero,
        // not ended); the others are the arm's transitions.
        let mut expected = Vec::new();
        let mut after_end = false;
        for (obs, out, _) in &next {
            if after_end {
                // The new episode's first observation: SAME_STEP's
                // observation of the step that ended the last one.
                let last: &mut (Vec<u64>, Outcome, Option<Vec<u64>>) = expected.last_mut().unwrap();
                last.2 = Some(last.0.clone());
                last.0 = row(obs);
                after_end = false;
                continue;
            }
            expected.push((row(obs), out[i], None));
            after_end = out[i].terminated || out[i].truncated;
        }
        // The last transition may be an end whose reset is past the trace.
        if after_end {
            expected.pop();
        }
        for (k, (obs, out, fin)) in expected.iter().enumerate() {
            let (s_obs, s_out, s_fin) = &same[k];
            assert_eq!(&row(s_obs), obs, "arm {i}, transition {k}: observation");
            assert_eq!(&s_out[i], out, "arm {i}, transition {k}: outcome");
            if let Some(f) = fin {
                assert_eq!(&row(s_fin), f, "arm {i}, transition {k}: final observation");
            }
        }
    }
}

#[test]
fn reset_options_apply_to_every_arm_or_one_each() {
    let count = 3;
    let mut envs = ArmEnvs::with_threads(plan(), opts(), count, 2).expect("envs");
    let (d, n) = (envs.obs_dim(), envs.envs()[0].dof());
    let mut obs = vec![0.0; count * d];
    let q = |x: f64| ResetOptions {
        initial_q: Some(vec![x; n]),
        initial_qd: None,
    };
    // Arm i as one environment reset with seed 5 + i and those options.
    let single = |i: usize, o: &ResetOptions| {
        let mut one = gym_env::ArmEnv::new(plan(), opts()).expect("env");
        let mut x = vec![0.0; d];
        one.reset_with(5 + i as u64, o, &mut x).expect("reset");
        bits(&x)
    };
    envs.reset_with(5, &[q(0.25)], &mut obs)
        .expect("one for all");
    for i in 0..count {
        assert_eq!(
            bits(&obs[i * d..(i + 1) * d]),
            single(i, &q(0.25)),
            "arm {i}"
        );
    }
    let each = [q(0.1), q(0.2), q(0.3)];
    envs.reset_with(5, &each, &mut obs).expect("one each");
    for (i, o) in each.iter().enumerate() {
        assert_eq!(bits(&obs[i * d..(i + 1) * d]), single(i, o), "arm {i}");
    }
    // The options changed the start: not the plain reset's.
    envs.reset(5, &mut obs).expect("reset");
    assert_ne!(bits(&obs[..d]), single(0, &q(0.1)));
    let e = envs.reset_with(5, &[q(0.1), q(0.2)], &mut obs).err();
    assert!(
        matches!(e, Some(EnvError::Option { ref name, .. }) if name == "options"),
        "{e:?}"
    );
}

#[test]
fn a_thread_count_out_of_range_is_refused_by_name() {
    for threads in [0, gym_env::MAX_THREADS + 1] {
        let e = ArmEnvs::with_threads(plan(), opts(), 2, threads).err();
        assert!(
            matches!(e, Some(EnvError::Option { ref name, .. }) if name == "num_threads"),
            "{threads}: {e:?}"
        );
    }
}
