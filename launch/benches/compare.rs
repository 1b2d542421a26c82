//! `testbed compare` on the paper scenario with one seed: on every core
//! and on one, so that the ratio shows the cores are used.
//!
//! `cargo bench -p launch --bench compare` (each sample is a whole
//! comparison of 8 laws × 20 s, about 4 s on two cores).

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use launch::compare::{CompareOptions, DEFAULT_LAWS, compare};

fn paper_compare(c: &mut Criterion) {
    let plan = scenario::load(None, &scenario::Overrides::default()).unwrap();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut group = c.benchmark_group("compare_paper_1_seed");
    group.sample_size(10);
    for threads in [cores, 1] {
        let opts = CompareOptions {
            laws: DEFAULT_LAWS.to_vec(),
            seeds: 1,
            threads: Some(threads),
            series: false,
        };
        group.bench_function(format!("{threads}_threads"), |b| {
            b.iter(|| compare(&plan, &opts).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, paper_compare);
criterion_main!(benches);
