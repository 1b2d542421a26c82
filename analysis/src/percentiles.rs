//! Percentiles of a stream of values in bounded memory: the figures of
//! every timing quantity and of each law's compute time.

use serde::Serialize;

/// p50, p99 and max of one quantity, in microseconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Percentiles {
    /// Median.
    pub p50: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Largest.
    pub max: f64,
    /// Samples.
    pub count: u64,
}

impl Percentiles {
    /// Nearest-rank percentiles of `values` (µs); zeros if empty.
    pub fn of(mut values: Vec<f64>) -> Self {
        if values.is_empty() {
            return Self {
                p50: 0.0,
                p99: 0.0,
                max: 0.0,
                count: 0,
            };
        }
        values.sort_by(f64::total_cmp);
        let rank =
            |p: f64| values[((p * values.len() as f64).ceil() as usize).clamp(1, values.len()) - 1];
        Self {
            p50: rank(0.50),
            p99: rank(0.99),
            max: values[values.len() - 1],
            count: values.len() as u64,
        }
    }
}

/// Samples kept exactly; past this a [`Quantiles`] folds them into a
/// histogram, so a run of any length needs bounded memory (8 MB a series).
pub const EXACT_SAMPLES: usize = 1 << 20;

/// Percentiles of a stream of values (µs) in bounded memory: exact for the
/// first [`EXACT_SAMPLES`], then within 0.1 % (log-spaced bins from 1 ns to
/// about 3 h); the largest value is always exact.
#[derive(Debug, Clone, Default)]
pub struct Quantiles {
    exact: Vec<f64>,
    bins: Vec<u64>,
    count: u64,
    max: f64,
}

/// Bins per factor of 10 in [`Quantiles`]'s histogram (0.1 % wide).
const BINS_PER_DECADE: f64 = 2300.0;
/// Decades the histogram covers, from 1e-3 µs.
const DECADES: f64 = 13.0;

impl Quantiles {
    /// Adds one value.
    pub fn add(&mut self, x: f64) {
        self.count += 1;
        self.max = if self.count == 1 { x } else { self.max.max(x) };
        if self.bins.is_empty() && self.exact.len() < EXACT_SAMPLES {
            self.exact.push(x);
            return;
        }
        if self.bins.is_empty() {
            self.bins = vec![0; (BINS_PER_DECADE * DECADES) as usize + 1];
            for v in std::mem::take(&mut self.exact) {
                let i = Self::bin(v);
                self.bins[i] += 1;
            }
        }
        let i = Self::bin(x);
        self.bins[i] += 1;
    }

    fn bin(x: f64) -> usize {
        let top = (BINS_PER_DECADE * DECADES) as usize;
        if x.is_nan() || x <= 1e-3 {
            return 0;
        }
        (((x / 1e-3).log10() * BINS_PER_DECADE) as usize).min(top)
    }

    fn value_of(bin: usize) -> f64 {
        1e-3 * 10f64.powf((bin as f64 + 0.5) / BINS_PER_DECADE)
    }

    /// p50, p99 and max of everything added (nearest rank).
    pub fn finish(&self) -> Percentiles {
        if self.bins.is_empty() {
            return Percentiles::of(self.exact.clone());
        }
        let rank = |p: f64| ((p * self.count as f64).ceil() as u64).clamp(1, self.count);
        let at = |r: u64| {
            let mut seen = 0;
            for (i, n) in self.bins.iter().enumerate() {
                seen += n;
                if seen >= r {
                    return Self::value_of(i).min(self.max);
                }
            }
            self.max
        };
        Percentiles {
            p50: at(rank(0.50)),
            p99: at(rank(0.99)),
            max: self.max,
            count: self.count,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentiles() {
        let p = Percentiles::of((1..=100).map(f64::from).collect());
        assert_eq!((p.p50, p.p99, p.max, p.count), (50.0, 99.0, 100.0, 100));
        let p = Percentiles::of(vec![3.0]);
        assert_eq!((p.p50, p.p99, p.max), (3.0, 3.0, 3.0));
        assert_eq!(Percentiles::of(vec![]).count, 0);
    }

    #[test]
    fn quantiles_stay_exact_then_bounded() {
        let mut q = Quantiles::default();
        for i in 1..=100 {
            q.add(f64::from(i));
        }
        let p = q.finish();
        assert_eq!((p.p50, p.p99, p.max, p.count), (50.0, 99.0, 100.0, 100));
        // Past the exact samples: a histogram, 0.1 % wide, memory bounded.
        let mut q = Quantiles::default();
        for i in 0..(EXACT_SAMPLES as u64 + 10) {
            q.add(if i % 100 == 99 { 1000.0 } else { 10.0 });
        }
        let p = q.finish();
        assert!((p.p50 - 10.0).abs() < 0.02, "{p:?}");
        assert!(
            (p.p99 - 10.0).abs() < 0.02 || (p.p99 - 1000.0).abs() < 2.0,
            "{p:?}"
        );
        assert_eq!(p.max, 1000.0);
        assert!(q.exact.is_empty() && q.bins.len() < 40_000);
    }
}
