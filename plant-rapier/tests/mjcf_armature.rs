//! An MJCF arm's armature is the plant's as it is the model's (#47): the
//! articulated engine's M(q) equals the laws' model's (arm_model's
//! dynamics, which add each joint's armature), and the scenario's
//! `[plant] armature` comes on top.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    reason = "test code: a broken expectation should fail loudly"
)]

use plant_rapier::{ArmModel, PerJoint, Plant, PlantConfig};

fn model() -> ArmModel {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../arm-model/tests/data/slide_armature.xml"
    );
    ArmModel::from_mjcf_file(std::path::Path::new(path), &Default::default()).unwrap()
}

/// M(q) of the model's own dynamics, column by column from inverse
/// dynamics at zero velocity.
fn model_inertia(model: &ArmModel, q: &[f64]) -> Vec<f64> {
    let n = model.dof();
    let mut d = arm_model::dynamics::Dynamics::new(model, 1.0);
    let zero = vec![0.0; n];
    let g = d.inverse(q, &zero, &zero).to_vec();
    let mut m = vec![0.0; n * n];
    for j in 0..n {
        let mut e = zero.clone();
        e[j] = 1.0;
        let col = d.inverse(q, &zero, &e);
        for i in 0..n {
            m[i * n + j] = col[i] - g[i];
        }
    }
    m
}

#[test]
fn an_mjcf_arms_armature_is_simulated_and_the_scenarios_is_added() {
    let model = model();
    let n = model.dof();
    let own: Vec<f64> = model
        .actuated
        .iter()
        .map(|&j| model.joints[j].armature)
        .collect();
    assert!(
        own.iter().any(|&a| a > 0.0),
        "the file gives armature: {own:?}"
    );
    let q: Vec<f64> = (0..n).map(|i| 0.2 + 0.1 * i as f64).collect();
    let want = model_inertia(&model, &q);
    let mut plant = Plant::new(&model, &PlantConfig::default()).unwrap();
    plant.set_state(&q, &vec![0.0; n]).unwrap();
    let (m, _) = plant.inertia_and_bias().unwrap();
    for (a, b) in m.iter().zip(&want) {
        assert!(
            (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
            "plant M {m:?}\nmodel M {want:?}"
        );
    }
    // The scenario's armature adds to the model's on the diagonal.
    let config = PlantConfig {
        armature: PerJoint::All(0.5),
        ..Default::default()
    };
    let mut plant = Plant::new(&model, &config).unwrap();
    plant.set_state(&q, &vec![0.0; n]).unwrap();
    let (m2, _) = plant.inertia_and_bias().unwrap();
    for i in 0..n {
        assert!(
            (m2[i * n + i] - m[i * n + i] - 0.5).abs() < 1e-12,
            "{m2:?} vs {m:?}"
        );
    }
}
