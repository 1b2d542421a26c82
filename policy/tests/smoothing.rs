//! The Rust node's smoothing is the environment's (#59 item 1): one
//! episode of a ramped policy that observes its last action, and of a
//! low-pass filtered one, played by the Gymnasium environment's core and by
//! [`policy::PolicyLaw`] stepping the same plant as lockstep does, give the
//! same states to the bit. Both act with the same network (tract), so any
//! difference is in how the action becomes a torque.

#![allow(
    clippy::unwrap_used,
    reason = "test code: a broken expectation should fail loudly"
)]

use std::path::Path;

use gym_env::{ActionMode, ArmEnv, EnvOptions, Smoothing};
use policy::{Policy, PolicyLaw};
use scenario::stepper::Stepper;

/// q after each decision of the environment's episode (seed 0).
fn env_episode(policy: &Policy, plan: scenario::Plan) -> (Vec<Vec<u64>>, scenario::Plan) {
    let r = policy.record();
    let opts = EnvOptions {
        action: ActionMode::Residual(r.base_law.unwrap()),
        residual_scale: r.residual_scale,
        torque_scale: Some(r.torque_scale.clone()),
        decimation: r.decimation,
        scale_obs: r.scale_obs,
        smoothing: r.smoothing,
        observe_action: r.observe_action,
        ..EnvOptions::default()
    };
    let mut env = ArmEnv::new(plan, opts).unwrap();
    let mut obs = vec![0.0; env.obs_dim()];
    assert_eq!(obs.len(), r.obs_dim);
    env.reset(0, &mut obs).unwrap();
    let drawn = env.plan().clone();
    let mut action = vec![0.0; env.dof()];
    let mut qs = Vec::new();
    for _ in 0..env.decisions() {
        policy.act(&obs, &mut action).unwrap();
        env.step(&action, &mut obs);
        qs.push(env.state().q[..2].iter().map(|x| x.to_bits()).collect());
    }
    (qs, drawn)
}

/// q after each decision's last period, the policy played as a law.
fn law_episode(policy: &Policy, plan: &scenario::Plan, decimation: u64) -> Vec<Vec<u64>> {
    let config = controller::node::ControllerNodeConfig {
        params: plan.scenario.controller.clone(),
        dof: 2,
        period_ns: plan.period_ns,
        reference_period_ns: plan.reference_period_ns,
        model: None,
        own_params: Default::default(),
        own_diagnostics: String::new(),
        scenario: String::new(),
    };
    let mut law = PolicyLaw::new(policy.clone(), &config).unwrap();
    let mut stepper = Stepper::new(plan).unwrap();
    let mut qs = Vec::new();
    while stepper.k() < stepper.steps() {
        let (cmd, _, err) = law.step(stepper.state(), Some(stepper.reference()));
        assert!(err.is_none());
        stepper.advance(&cmd).unwrap();
        if stepper.k().is_multiple_of(decimation) || stepper.k() == stepper.steps() {
            qs.push(stepper.state().q[..2].iter().map(|x| x.to_bits()).collect());
        }
    }
    qs
}

#[test]
fn the_nodes_ramp_and_low_pass_are_the_environments_to_the_bit() {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    for (file, smoothing) in [
        ("ramp_observed.onnx", Smoothing::Ramp),
        ("low_pass.onnx", Smoothing::LowPass { tau_s: 0.01 }),
    ] {
        let policy = Policy::load(&fixtures.join(file)).unwrap();
        assert_eq!(policy.record().smoothing, smoothing);
        let plan = scenario::load_named(
            Some(Path::new("paper")),
            &scenario::Overrides {
                // The record's episode (steps 4000): the observation's
                // time fraction is k / steps in both.
                duration_s: Some(4.0),
                ..Default::default()
            },
        )
        .unwrap();
        let (from_env, drawn) = env_episode(&policy, plan);
        let from_law = law_episode(&policy, &drawn, u64::from(policy.record().decimation));
        assert_eq!(from_env.len(), 200, "{file}");
        assert_eq!(from_env, from_law, "{file}: the states differ");
    }
}

#[test]
fn a_low_pass_has_no_step_where_a_hold_has_one() {
    // The same actions held and low-pass filtered: the torque's largest change from
    // one period to the next.
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let policy = Policy::load(&fixtures.join("low_pass.onnx")).unwrap();
    let jump = |smoothing| {
        let plan = scenario::load_named(Some(Path::new("paper")), &Default::default()).unwrap();
        let r = policy.record();
        let opts = EnvOptions {
            action: ActionMode::Residual(r.base_law.unwrap()),
            torque_scale: Some(r.torque_scale.clone()),
            scale_obs: false,
            smoothing,
            decimation: 1,
            ..EnvOptions::default()
        };
        let mut env = ArmEnv::new(plan, opts).unwrap();
        let mut obs = vec![0.0; env.obs_dim()];
        env.reset(0, &mut obs).unwrap();
        env.step(&[0.0, 0.0], &mut obs);
        let (mut last, mut worst) = (env.last_torque().to_vec(), 0.0f64);
        // One action of +1 then one of −1, at one period a decision: the
        // residual's span is 0.2 · 50 N m each way.
        for a in [[1.0, 1.0], [-1.0, -1.0]] {
            env.step(&a, &mut obs);
            worst = worst.max((env.last_torque()[0] - last[0]).abs());
            last = env.last_torque().to_vec();
        }
        worst
    };
    let held = jump(Smoothing::Hold);
    let filtered = jump(Smoothing::LowPass { tau_s: 0.01 });
    assert!(held > 15.0, "held {held}");
    assert!(
        filtered < 0.2 * held,
        "low-pass {filtered} against held {held}"
    );
}
