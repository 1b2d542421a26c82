//! The policy crate on ONNX files made by the exporter
//! (`tests/fixtures/make.py`, `testbed.onnx_export`): loading, the
//! record, refusals by file and field, and the network's numbers.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use std::path::{Path, PathBuf};

use policy::{Policy, PolicyError};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// make.py's weights.
fn w(i: usize, j: usize) -> f64 {
    (i + 1) as f64 * (j as f64 - 7.0) / 100.0
}

#[test]
fn a_linear_policy_loads_with_its_record_and_computes_w_obs_plus_b() {
    let p = Policy::load(&fixture("linear.onnx")).unwrap();
    let r = p.record();
    assert_eq!((r.dof, r.obs_dim, r.steps, r.decimation), (2, 15, 4000, 20));
    assert!(r.scale_obs);
    assert_eq!(r.velocity_scale, [1.0, 2.0]);
    assert_eq!(r.base_law, Some(controller::LawName::Pd));
    assert_eq!(r.rest["scenario"], "paper");
    let obs: Vec<f64> = (0..15).map(|j| 0.1 * j as f64 - 0.3).collect();
    let mut a = [0.0; 2];
    p.act(&obs, &mut a).unwrap();
    let b = [0.1, -0.2];
    for i in 0..2 {
        let want = ((0..15).map(|j| w(i, j) * obs[j]).sum::<f64>() + b[i]).clamp(-1.0, 1.0);
        // tract's f64 kernel may sum in another order: to round-off.
        assert!((a[i] - want).abs() < 1e-14, "{i}: {} against {want}", a[i]);
    }
    // Clipped in the network as LinearPolicy.act clips.
    let far: Vec<f64> = (0..15).map(|j| 10.0 * j as f64).collect();
    p.act(&far, &mut a).unwrap();
    assert_eq!(a, [1.0, 1.0]);
}

#[test]
fn a_model_without_the_record_is_refused_naming_the_file() {
    let e = Policy::load(&fixture("no_metadata.onnx")).unwrap_err();
    assert!(matches!(e, PolicyError::NoMetadata { .. }), "{e:?}");
    let text = e.to_string();
    assert!(
        text.contains("no_metadata.onnx") && text.contains("testbed.env"),
        "{text}"
    );
}

#[test]
fn a_network_whose_input_is_not_the_records_obs_dim_is_refused() {
    let e = Policy::load(&fixture("wrong_dof.onnx")).unwrap_err();
    let PolicyError::Shape { which, need, .. } = &e else {
        panic!("expected a shape refusal, got {e:?}");
    };
    assert_eq!(*which, "input");
    assert!(need.contains("22"), "{e}");
    assert!(e.to_string().contains("wrong_dof.onnx"), "{e}");
}

#[test]
fn an_integer_output_is_refused() {
    let e = Policy::load(&fixture("int_output.onnx")).unwrap_err();
    assert!(matches!(e, PolicyError::OutputType { .. }), "{e:?}");
    assert!(e.to_string().contains("int_output.onnx"), "{e}");
}

#[test]
fn a_file_that_is_not_onnx_is_refused_naming_it() {
    let e = Policy::load(&fixture("make.py")).unwrap_err();
    assert!(matches!(e, PolicyError::NotOnnx { .. }), "{e:?}");
    assert!(e.to_string().contains("make.py"), "{e}");
    let e = Policy::from_bytes(b"", Path::new("empty.onnx")).unwrap_err();
    assert!(matches!(e, PolicyError::NotOnnx { .. }), "{e:?}");
    let e = Policy::load(&fixture("absent.onnx")).unwrap_err();
    assert!(matches!(e, PolicyError::Read { .. }), "{e:?}");
}

#[test]
fn a_non_finite_output_is_an_error_naming_the_component() {
    let p = Policy::load(&fixture("nan.onnx")).unwrap();
    let e = p.act(&[0.0; 15], &mut [0.0; 2]).unwrap_err();
    match e {
        PolicyError::NotFinite { index, .. } => assert_eq!(index, 0),
        e => panic!("expected NotFinite, got {e:?}"),
    }
}

/// The run's config for a pd base law on two joints at 1 kHz.
fn pd_config() -> controller::node::ControllerNodeConfig {
    controller::node::ControllerNodeConfig {
        params: controller::ControllerParams {
            law: controller::LawName::Pd,
            ..Default::default()
        },
        dof: 2,
        period_ns: 1_000_000,
        reference_period_ns: 0,
        model: None,
        own_params: Default::default(),
        own_diagnostics: String::new(),
        scenario: String::new(),
    }
}

/// State k of a made-up motion and a reference with k_c = 0.5.
fn sample(k: u64) -> (wire::JointState, wire::ReferenceSample) {
    let mut s = wire::JointState::default();
    s.header.seq = k;
    s.header.t_ns = k * 1_000_000;
    let mut r = wire::ReferenceSample::default();
    r.header.t_ns = s.header.t_ns;
    for i in 0..2 {
        s.q_measured[i] = 0.01 * k as f64 + i as f64;
        s.qd_measured[i] = 0.3 - 0.02 * k as f64;
        s.q[i] = s.q_measured[i];
        s.qd[i] = s.qd_measured[i];
        r.q_d[i] = 0.5 * i as f64;
        r.kc[i] = 0.5;
    }
    (s, r)
}

#[test]
fn the_action_is_taken_every_decimation_periods_held_and_added_to_the_base_law() {
    let policy = Policy::load(&fixture("linear.onnx")).unwrap();
    let r = policy.record().clone();
    let mut law = policy::PolicyLaw::new(policy.clone(), &pd_config()).unwrap();
    let mut base = pd_config().machine().unwrap();
    let (mut obs, mut action, mut held) = (vec![0.0; 15], [0.0; 2], [0.0; 2]);
    let mut changes = 0;
    for k in 0..45u64 {
        let (s, reference) = sample(k);
        let (cmd, diag, err) = law.step(&s, Some(&reference));
        assert!(err.is_none());
        if k % 20 == 0 {
            // The environment's observation and action map, by hand.
            gym_env::observe(
                &s,
                &reference,
                k,
                r.steps,
                true,
                &r.velocity_scale,
                &mut obs,
            );
            policy.act(&obs, &mut action).unwrap();
            let before = held;
            gym_env::action_torque(&action, r.span(), &r.torque_scale, &mut held);
            changes += usize::from(before != held);
        }
        let (want, _) = base.step(&s, Some(&reference));
        for (i, h) in held.iter().enumerate() {
            assert_eq!(
                cmd.tau[i].to_bits(),
                (want.tau[i] + h).to_bits(),
                "k {k}, joint {i}"
            );
        }
        assert_eq!(diag.tau[..2], cmd.tau[..2]);
    }
    assert_eq!(changes, 3, "a new action at k = 0, 20 and 40 only");
}

#[test]
fn without_a_reference_the_torque_is_zero_with_the_fault() {
    let policy = Policy::load(&fixture("linear.onnx")).unwrap();
    let mut law = policy::PolicyLaw::new(policy, &pd_config()).unwrap();
    let (s, _) = sample(0);
    let (cmd, _, err) = law.step(&s, None);
    assert!(err.is_none());
    assert_eq!(cmd.tau, [0.0; wire::MAX_DOF]);
    assert_eq!(cmd.fault, wire::Fault::NoReference.code());
}
