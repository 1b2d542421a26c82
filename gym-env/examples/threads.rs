//! Arm-steps a second of 64 arms on 1 thread and on every CPU, from
//! Rust (no Python in the loop): `cargo run --release -p gym-env
//! --example threads [DECIMATION]`.

use gym_env::{ArmEnvs, EnvOptions, Outcome};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let decimation: u32 = std::env::args().nth(1).map_or(Ok(1), |a| a.parse())?;
    let plan = scenario::load_named(
        None,
        &scenario::Overrides {
            duration_s: Some(1000.0),
            ..Default::default()
        },
    )?;
    let opts = EnvOptions {
        decimation,
        ..EnvOptions::default()
    };
    for threads in [1, gym_env::default_threads(), 1, gym_env::default_threads()] {
        let mut envs = ArmEnvs::with_threads(plan.clone(), opts.clone(), 64, threads)?;
        let (d, n) = (envs.obs_dim(), envs.envs()[0].dof());
        let mut obs = vec![0.0; 64 * d];
        let mut out = vec![Outcome::default(); 64];
        let actions = vec![0.0; 64 * n];
        envs.reset(0, &mut obs)?;
        let calls = 20_000 / decimation as usize;
        let start = std::time::Instant::now();
        for _ in 0..calls {
            envs.step(&actions, &mut obs, &mut out)?;
        }
        let s = start.elapsed().as_secs_f64();
        println!(
            "{threads} threads: {:.0} arm-steps/s, {:.1} µs a call",
            (calls * 64) as f64 / s,
            s / calls as f64 * 1e6
        );
    }
    Ok(())
}
