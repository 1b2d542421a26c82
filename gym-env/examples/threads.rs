//! Arm-steps of 64 arms on 1 thread and on every CPU, from Rust (no
//! Python in the loop), and the machine's own ceiling for the same work:
//! the arms split into one independent vector per CPU, each stepped on its
//! own OS thread with no pool and no sharing between calls. The pool's
//! ratio over 1 thread is judged against that ceiling's, measured in the
//! same run: on a virtual machine two "CPUs" can be one core's
//! hyperthreads, and no pool goes faster than independent threads.
//! `cargo run --release -p gym-env --example threads [DECIMATION] [ROUNDS]`.

use gym_env::{ArmEnvs, EnvOptions, Outcome};
use scenario::Plan;

const ARMS: usize = 64;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let decimation: u32 = args.next().map_or(Ok(20), |a| a.parse())?;
    let rounds: usize = args.next().map_or(Ok(3), |a| a.parse())?;
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
    let cpus = gym_env::default_threads();
    let calls = 20_000 / decimation as usize;
    println!("{ARMS} arms, decimation {decimation}, {calls} calls a row, {cpus} CPUs");
    let (mut pool, mut ceiling) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        let one = pooled(&plan, &opts, 1, calls)?;
        let many = pooled(&plan, &opts, cpus, calls)?;
        let apart = independent(&plan, &opts, cpus, calls)?;
        println!(
            "1 thread {one:.0}, pool of {cpus} {many:.0}, {cpus} independent {apart:.0} arm-steps/s: pool {:.2}x, ceiling {:.2}x",
            many / one,
            apart / one
        );
        pool.push(many / one);
        ceiling.push(apart / one);
    }
    println!(
        "median: pool {:.2}x, ceiling {:.2}x, pool / ceiling {:.2}",
        median(&mut pool),
        median(&mut ceiling),
        median(&mut pool) / median(&mut ceiling)
    );
    Ok(())
}

/// Arm-steps a second of one vector of [`ARMS`] arms on `threads` threads.
fn pooled(
    plan: &Plan,
    opts: &EnvOptions,
    threads: usize,
    calls: usize,
) -> Result<f64, gym_env::EnvError> {
    let seconds = run(plan, opts, ARMS, threads, calls)?;
    Ok((calls * ARMS) as f64 / seconds)
}

/// Arm-steps a second of `cpus` vectors of ARMS / cpus arms, each stepped
/// on its own thread.
fn independent(
    plan: &Plan,
    opts: &EnvOptions,
    cpus: usize,
    calls: usize,
) -> Result<f64, gym_env::EnvError> {
    let share = ARMS / cpus;
    let seconds = std::thread::scope(|s| {
        let handles: Vec<_> = (0..cpus)
            .map(|_| s.spawn(|| run(plan, opts, share, 1, calls)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or(Ok(f64::INFINITY)))
            .try_fold(0.0_f64, |worst, t| t.map(|t| worst.max(t)))
    })?;
    Ok((calls * share * cpus) as f64 / seconds)
}

/// Seconds `calls` steps of `arms` arms on `threads` threads take.
fn run(
    plan: &Plan,
    opts: &EnvOptions,
    arms: usize,
    threads: usize,
    calls: usize,
) -> Result<f64, gym_env::EnvError> {
    let mut envs = ArmEnvs::with_threads(plan.clone(), opts.clone(), arms, threads)?;
    let (d, n) = (envs.obs_dim(), envs.envs()[0].dof());
    let mut obs = vec![0.0; arms * d];
    let mut out = vec![Outcome::default(); arms];
    let actions = vec![0.0; arms * n];
    envs.reset(0, &mut obs)?;
    let start = std::time::Instant::now();
    for _ in 0..calls {
        envs.step(&actions, &mut obs, &mut out)?;
    }
    Ok(start.elapsed().as_secs_f64())
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
