//! `testbed compare` on the paper scenario with one seed, on the randomised
//! paper scenario with 20 seeds, and a sweep of 16 runs: each on every core and on one, so that the ratio shows the
//! cores are used.
//!
//! `cargo bench -p experiments --bench compare` (each sample is a whole
//! comparison of 8 laws × 20 s, about 4 s on two cores, or a whole sweep).

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    missing_docs,
    reason = "bench code: a broken expectation should fail loudly"
)]

use criterion::{Criterion, criterion_group, criterion_main};
use experiments::compare::{CompareOptions, DEFAULT_LAWS, compare};

fn paper_compare(c: &mut Criterion) {
    let plan = scenario::load(None, &scenario::Overrides::default()).unwrap();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut group = c.benchmark_group("compare_paper_1_seed");
    group.sample_size(10);
    for threads in [cores, 1] {
        let opts = CompareOptions {
            law_sets: Vec::new(),
            external: Vec::new(),
            runs_dir: std::path::PathBuf::from("runs"),
            progress: false,
            laws: DEFAULT_LAWS.to_vec(),
            seeds: 1,
            threads: Some(threads),
            series: false,
            tuning: None,
        };
        group.bench_function(format!("{threads}_threads"), |b| {
            b.iter(|| compare(&plan, &opts).unwrap())
        });
    }
    group.finish();
}

/// `compare --seeds 20` on the randomised paper scenario (5 s runs): 160
/// runs with their draws, quartiles, intervals and paired tests.
fn randomised_compare(c: &mut Criterion) {
    let path = scenario::find_shipped("paper_randomised").unwrap().path();
    let overrides = scenario::Overrides {
        duration_s: Some(5.0),
        ..Default::default()
    };
    let plan = scenario::load(Some(&path), &overrides).unwrap();
    let opts = CompareOptions {
        law_sets: Vec::new(),
        external: Vec::new(),
        runs_dir: std::path::PathBuf::from("runs"),
        progress: false,
        laws: DEFAULT_LAWS.to_vec(),
        seeds: 20,
        threads: None,
        series: false,
        tuning: None,
    };
    let mut group = c.benchmark_group("compare_randomised_20_seeds");
    group.sample_size(10);
    group.bench_function("all_threads", |b| b.iter(|| compare(&plan, &opts).unwrap()));
    group.finish();
}

/// 16 runs of 5 s (2 × 2 gains × 4 seeds of sensor noise) into a fresh
/// results folder per iteration: the sweep's throughput.
fn sweep_throughput(c: &mut Criterion) {
    let root = tempfile::tempdir().unwrap();
    let file = root.path().join("bench.toml");
    std::fs::write(
        &file,
        "seeds = 4\n[set]\nduration_s = 5.0\n\"plant.sensor.q_noise_std\" = 0.001\n\
         [[axis]]\nkey = \"controller.k1\"\nvalues = [10.0, 20.0]\n\
         [[axis]]\nkey = \"controller.k2\"\nvalues = [10.0, 15.0]\n",
    )
    .unwrap();
    let sweep = experiments::sweep::file::load(&file).unwrap();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let stop = std::sync::atomic::AtomicBool::new(false);
    let mut group = c.benchmark_group("sweep_16_runs");
    group.sample_size(10);
    let mut k = 0;
    for threads in [cores, 1] {
        let opts = experiments::sweep::RunOptions {
            threads: Some(threads),
            share: None,
            progress: false,
        };
        group.bench_function(format!("{threads}_threads"), |b| {
            b.iter(|| {
                k += 1;
                let dir = root.path().join(format!("r{k}"));
                experiments::sweep::run(&sweep, &dir, &opts, &stop).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, paper_compare, randomised_compare, sweep_throughput);
criterion_main!(benches);
