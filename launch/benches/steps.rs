//! One controller step and one plant step, for the paper's two-link arm,
//! the UR5 (6 joints) and the KUKA iiwa 14 (7 joints), at seeded random
//! states, with the default plant settings.
//! `cargo bench -p launch --bench steps`.

#![allow(
    missing_docs,
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "bench code: a broken expectation should fail loudly"
)]

use controller::{Controller, ControllerInput, ControllerParams};
use criterion::{Criterion, criterion_group, criterion_main};
use plant_rapier::{ArmModel, Plant, PlantConfig};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const ARMS: [(&str, &str); 3] = [
    ("two_link", include_str!("../../robots/two_link.urdf")),
    ("ur5", include_str!("../../robots/ur5.urdf")),
    ("iiwa14", include_str!("../../robots/iiwa14.urdf")),
];

fn controller_step(c: &mut Criterion) {
    for (name, urdf) in ARMS {
        let n = ArmModel::from_urdf_str(urdf).unwrap().dof();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut v =
            |scale: f64| -> Vec<f64> { (0..n).map(|_| rng.random_range(-scale..scale)).collect() };
        let (q, qd, q_d, qd_d, qdd_d, kc_dot) = (v(1.0), v(1.0), v(1.0), v(1.0), v(1.0), v(0.1));
        let kc = vec![0.5; n];
        let mut law = Controller::new(ControllerParams::default(), n).unwrap();
        let mut diag = law.diagnostics();
        let mut t = 0.0;
        c.bench_function(&format!("controller_step_{name}_{n}dof"), |b| {
            b.iter(|| {
                t += 1e-3;
                let input = ControllerInput {
                    t,
                    q: &q,
                    qd: &qd,
                    q_d: &q_d,
                    qd_d: &qd_d,
                    qdd_d: &qdd_d,
                    kc: &kc,
                    kc_dot: &kc_dot,
                };
                law.step(1e-3, &input, &mut diag);
                std::hint::black_box(diag.tau[0])
            })
        });
    }
}

fn plant_step(c: &mut Criterion) {
    for (name, urdf) in ARMS {
        let model = ArmModel::from_urdf_str(urdf).unwrap();
        let n = model.dof();
        let mut plant = Plant::new(&model, &PlantConfig::default()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let q: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        plant.set_state(&q, &vec![0.0; n]).unwrap();
        let tau: Vec<f64> = (0..n).map(|_| rng.random_range(-2.0..2.0)).collect();
        let substeps = plant.substeps();
        c.bench_function(
            &format!("plant_step_{name}_{n}dof_{substeps}substeps"),
            |b| {
                b.iter(|| {
                    plant.step(&tau, 1e-3).unwrap();
                    std::hint::black_box(plant.applied_torque()[0])
                })
            },
        );
    }
}

criterion_group!(benches, controller_step, plant_step);
criterion_main!(benches);
