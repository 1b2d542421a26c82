//! Steps one arm's plant a fixed number of times from a seeded random state,
//! for instruction counts that do not move with the machine's load:
//! `valgrind --tool=callgrind target/release/examples/plant_steps robots/iiwa14.urdf 2000`.

use std::process::ExitCode;

use plant_rapier::{ArmModel, Plant, PlantConfig};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let (Some(path), Some(steps)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: plant_steps URDF STEPS");
        return ExitCode::from(2);
    };
    match run(path, steps) {
        Ok(q) => {
            println!("q after the run: {q:?}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("plant_steps: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(path: &str, steps: &str) -> Result<Vec<f64>, Box<dyn std::error::Error>> {
    let steps: u32 = steps.parse()?;
    let model = ArmModel::from_urdf_str(&std::fs::read_to_string(path)?)?;
    let n = model.dof();
    let mut plant = Plant::new(&model, &PlantConfig::default())?;
    // The state and torques of the criterion bench `plant_step`.
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let q: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
    plant.set_state(&q, &vec![0.0; n])?;
    let tau: Vec<f64> = (0..n).map(|_| rng.random_range(-2.0..2.0)).collect();
    for _ in 0..steps {
        plant.step(&tau, 1e-3)?;
    }
    Ok(plant.state().0)
}
