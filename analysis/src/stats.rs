//! Statistics over seeds: quantiles, a distribution-free 95 % interval for
//! the median, the interquartile mean with a stratified-bootstrap interval
//! (rliable's recommendation for few runs), the Wilcoxon signed-rank test on paired runs, and the exact
//! tests of yes/no outcomes (McNemar's on paired runs, the binomial bound
//! on a rate seen without a failure).
//!
//! Values may be +∞ or −∞ (a failed run's metric counts as the worst), so
//! everything here orders with `total_cmp` and never subtracts two
//! infinities.

use serde::Serialize;

/// The p-quantile of sorted values by linear interpolation (NaN if empty).
pub fn quantile(v: &[f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let h = (v.len() - 1) as f64 * p;
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    let (a, b) = (v[lo], v[hi]);
    if a == b {
        a
    } else {
        a + (h - lo as f64) * (b - a)
    }
}

/// The interquartile mean of sorted values: the mean of the middle half,
/// x(⌊n/4⌋+1) … x(⌈3n/4⌉) (rliable's IQM; for n < 4 the plain mean). An
/// infinite value inside the middle half makes it infinite; one in the
/// outer quarters does not count. NaN if empty.
pub fn iqm(v: &[f64]) -> f64 {
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    let (lo, hi) = (n / 4, n - n / 4);
    let mid = &v[lo..hi.max(lo + 1)];
    mid.iter().sum::<f64>() / mid.len() as f64
}

/// The median over seeds of (a_i − b_i) / |b_i|, the paired effect of a
/// against b (never a ratio of medians of different seeds): −∞ where only
/// b failed (a failed run is the worst, +∞), +∞ where only a did, 0 where
/// both did or the two are equal.
pub fn median_relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let mut d: Vec<f64> = a
        .iter()
        .zip(b)
        .map(|(&x, &y)| match (x.is_finite(), y.is_finite()) {
            _ if x == y => 0.0,
            (true, true) if y != 0.0 => (x - y) / y.abs(),
            (true, true) => (x - y).signum() * f64::INFINITY,
            (true, false) => f64::NEG_INFINITY,
            (false, true) => f64::INFINITY,
            (false, false) => 0.0,
        })
        .collect();
    d.sort_by(f64::total_cmp);
    quantile(&d, 0.5)
}

/// How many resamples [`iqm_interval`] draws.
pub const BOOTSTRAP_RESAMPLES: usize = 2000;

/// A 95 % percentile interval for the IQM by the stratified bootstrap:
/// each stratum (one task, one stress level) is resampled with replacement
/// within itself and the IQM taken over the pooled resample (Agarwal et
/// al. 2021, rliable). Seeded, so the same values give the same interval
/// on any machine. None if there are no values.
pub fn iqm_interval(strata: &[&[f64]], seed: u64) -> Option<(f64, f64)> {
    use rand::{Rng, SeedableRng};
    let n: usize = strata.iter().map(|s| s.len()).sum();
    if n == 0 {
        return None;
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut pooled = Vec::with_capacity(n);
    let mut stats = Vec::with_capacity(BOOTSTRAP_RESAMPLES);
    for _ in 0..BOOTSTRAP_RESAMPLES {
        pooled.clear();
        for s in strata.iter().filter(|s| !s.is_empty()) {
            pooled.extend((0..s.len()).map(|_| s[rng.random_range(0..s.len())]));
        }
        pooled.sort_by(f64::total_cmp);
        stats.push(iqm(&pooled));
    }
    stats.sort_by(f64::total_cmp);
    Some((quantile(&stats, 0.025), quantile(&stats, 0.975)))
}

/// A 95 % confidence interval for the median from order statistics.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MedianInterval {
    /// The k-th smallest value (1-based `k`).
    pub low: f64,
    /// The (n + 1 − k)-th smallest value.
    pub high: f64,
    /// The rank k.
    pub k: usize,
    /// P(low ≤ median ≤ high) for any continuous distribution: ≥ 0.95,
    /// or the largest possible when n < 6 (the whole range).
    pub coverage: f64,
}

/// The order-statistic interval [x(k), x(n+1−k)] for the median of sorted
/// values `v`, with the largest k whose coverage 1 − 2 P(B ≤ k−1),
/// B ~ Binomial(n, ½), is still ≥ 95 % (None if `v` is empty).
pub fn median_interval(v: &[f64]) -> Option<MedianInterval> {
    let n = v.len();
    if n == 0 {
        return None;
    }
    let cdf = binomial_half_cdf(n);
    // cdf[j] = P(B ≤ j); k − 1 = j.
    let k = (1..=n.div_ceil(2))
        .take_while(|&k| 2.0 * cdf[k - 1] <= 0.05)
        .last()
        .unwrap_or(1);
    Some(MedianInterval {
        low: v[k - 1],
        high: v[n - k],
        k,
        coverage: 1.0 - 2.0 * cdf[k - 1],
    })
}

/// P(B ≤ j) for j = 0..=n, B ~ Binomial(n, ½).
fn binomial_half_cdf(n: usize) -> Vec<f64> {
    // Row n of Pascal's triangle times 2^-n, built in probabilities so
    // that large n do not overflow.
    let mut p = vec![1.0];
    for _ in 0..n {
        let mut next = vec![0.0; p.len() + 1];
        for (j, x) in p.iter().enumerate() {
            next[j] += 0.5 * x;
            next[j + 1] += 0.5 * x;
        }
        p = next;
    }
    p.iter()
        .scan(0.0, |acc, x| {
            *acc += x;
            Some(*acc)
        })
        .collect()
}

/// McNemar's exact test of paired yes/no outcomes (e.g. "kept the
/// envelope") of two laws on the same seeds: only the discordant seeds
/// count, and under H0 each is either law's with probability ½.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct McNemar {
    /// Seeds where only the first law had the outcome.
    pub a_only: usize,
    /// Seeds where only the second law had it.
    pub b_only: usize,
    /// Two-sided exact p: 2 P(B ≤ min(a_only, b_only)), B ~ Binomial(a_only
    /// + b_only, ½), at most 1 (1 when no seed is discordant).
    pub p_value: f64,
}

/// [`McNemar`] from the discordant counts.
pub fn mcnemar_exact(a_only: usize, b_only: usize) -> McNemar {
    let n = a_only + b_only;
    let p_value = if n == 0 {
        1.0
    } else {
        (2.0 * binomial_half_cdf(n)[a_only.min(b_only)]).min(1.0)
    };
    McNemar {
        a_only,
        b_only,
        p_value,
    }
}

/// The exact one-sided lower confidence bound (level 1 − `alpha`) on a
/// rate seen n times out of n (Clopper–Pearson): `alpha`^(1/n); 0 for n = 0.
pub fn all_of_n_lower_bound(n: usize, alpha: f64) -> f64 {
    if n == 0 {
        0.0
    } else {
        alpha.powf(1.0 / n as f64)
    }
}

/// The Wilcoxon signed-rank test of paired values a_i, b_i.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SignedRank {
    /// Pairs.
    pub pairs: usize,
    /// Pairs with a < b.
    pub a_smaller: usize,
    /// Pairs with a > b.
    pub b_smaller: usize,
    /// Pairs with a = b (left out of the test, as Wilcoxon does).
    pub ties: usize,
    /// The median of a_i − b_i (±∞ when failed runs dominate).
    pub median_difference: f64,
    /// Sum of the ranks of |a_i − b_i| over the pairs with a > b.
    pub w_plus: f64,
    /// Two-sided p-value (1 when every pair ties).
    pub p_value: f64,
    /// "exact" (the permutation distribution, mid-ranks for tied |d|) or
    /// "normal" (with tie and continuity corrections, past 200 pairs).
    pub method: &'static str,
}

/// Pairs past which the p-value comes from the normal approximation.
const EXACT_UP_TO: usize = 200;

/// The test of a against b; a_i − b_i of two equal values (also two
/// equal infinities) is a tie.
pub fn signed_rank(a: &[f64], b: &[f64]) -> SignedRank {
    let d: Vec<f64> = a
        .iter()
        .zip(b)
        .map(|(x, y)| if x == y { 0.0 } else { x - y })
        .map(|d| if d.is_nan() { 0.0 } else { d })
        .collect();
    let mut sorted = d.clone();
    sorted.sort_by(f64::total_cmp);
    let nonzero: Vec<f64> = d.iter().copied().filter(|x| *x != 0.0).collect();
    let ranks = mid_ranks(&nonzero);
    // fold from +0.0: an empty `sum` of f64 is −0.0.
    let w_plus = nonzero
        .iter()
        .zip(&ranks)
        .filter(|(d, _)| **d > 0.0)
        .fold(0.0, |w, (_, r)| w + r);
    let n = nonzero.len();
    let (p_value, method) = if n == 0 {
        (1.0, "exact")
    } else if n <= EXACT_UP_TO {
        (exact_p(&ranks, w_plus), "exact")
    } else {
        (normal_p(&ranks, w_plus), "normal")
    };
    SignedRank {
        pairs: d.len(),
        a_smaller: d.iter().filter(|x| **x < 0.0).count(),
        b_smaller: d.iter().filter(|x| **x > 0.0).count(),
        ties: d.len() - n,
        median_difference: quantile(&sorted, 0.5),
        w_plus,
        p_value,
        method,
    }
}

/// Ranks of |d| (1-based), tied magnitudes sharing their mean rank.
fn mid_ranks(d: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..d.len()).collect();
    order.sort_by(|&i, &j| d[i].abs().total_cmp(&d[j].abs()));
    let mut ranks = vec![0.0; d.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && d[order[j + 1]].abs() == d[order[i]].abs() {
            j += 1;
        }
        let mean = (i + j) as f64 / 2.0 + 1.0;
        order[i..=j].iter().for_each(|&k| ranks[k] = mean);
        i = j + 1;
    }
    ranks
}

/// Two-sided p from the exact distribution of W+ under H0 (each sign ½),
/// over doubled ranks so that mid-ranks stay integers.
fn exact_p(ranks: &[f64], w_plus: f64) -> f64 {
    let doubled: Vec<usize> = ranks.iter().map(|r| (2.0 * r).round() as usize).collect();
    let total: usize = doubled.iter().sum();
    let mut p = vec![0.0; total + 1];
    p[0] = 1.0;
    let mut reach = 0;
    for &r in &doubled {
        for w in (0..=reach).rev() {
            let x = p[w] * 0.5;
            p[w] = x;
            p[w + r] += x;
        }
        reach += r;
    }
    let w = (2.0 * w_plus).round() as usize;
    let below: f64 = p[..=w].iter().sum();
    let above: f64 = p[w..].iter().sum();
    (2.0 * below.min(above)).min(1.0)
}

/// Two-sided p from the normal approximation with tie and continuity
/// corrections.
fn normal_p(ranks: &[f64], w_plus: f64) -> f64 {
    let n = ranks.len() as f64;
    let mean = n * (n + 1.0) / 4.0;
    let mut sorted = ranks.to_vec();
    sorted.sort_by(f64::total_cmp);
    let ties: f64 = sorted
        .chunk_by(|a, b| a == b)
        .map(|g| {
            let t = g.len() as f64;
            t * t * t - t
        })
        .sum();
    let var = n * (n + 1.0) * (2.0 * n + 1.0) / 24.0 - ties / 48.0;
    let dev = ((w_plus - mean).abs() - 0.5).max(0.0);
    libm::erfc(dev / var.sqrt() / std::f64::consts::SQRT_2).min(1.0)
}

#[cfg(test)]
mod iqm_tests {
    use super::*;

    #[test]
    fn the_iqm_is_the_mean_of_the_middle_half() {
        let v = [-50.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 100.0];
        assert_eq!(iqm(&v), 3.5);
        assert_eq!(iqm(&[2.0]), 2.0);
        assert!(iqm(&[]).is_nan());
        // A worst value (a failed run) in the top quarter does not count.
        assert_eq!(iqm(&[1.0, 2.0, 3.0, f64::INFINITY]), 2.5);
    }

    #[test]
    fn the_interval_holds_the_iqm_narrows_with_data_and_repeats() {
        let x: Vec<f64> = (0..20).map(|i| ((i * 37) % 20) as f64).collect();
        let mut sorted = x.clone();
        sorted.sort_by(f64::total_cmp);
        let (lo, hi) = iqm_interval(&[&x], 7).unwrap();
        assert!(lo < iqm(&sorted) && iqm(&sorted) < hi, "{lo} {hi}");
        assert_eq!(iqm_interval(&[&x], 7), Some((lo, hi)));
        let many: Vec<f64> = (0..400).map(|i| ((i * 37) % 20) as f64).collect();
        let (lo2, hi2) = iqm_interval(&[&many], 7).unwrap();
        assert!(hi2 - lo2 < hi - lo);
        // Strata are resampled apart: two constant strata give one value.
        let (a, b) = ([1.0; 5], [3.0; 15]);
        let (lo, hi) = iqm_interval(&[&a, &b], 1).unwrap();
        assert_eq!((lo, hi), (3.0, 3.0));
        assert_eq!(iqm_interval(&[], 1), None);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mcnemar_is_the_exact_binomial_tail_of_the_discordant_seeds() {
        // 6 to 0: 2 / 2^6.
        assert!((mcnemar_exact(6, 0).p_value - 2.0 / 64.0).abs() < 1e-15);
        assert_eq!(mcnemar_exact(0, 6).p_value, mcnemar_exact(6, 0).p_value);
        // 2 to 0 and 1 to 1 show nothing: p = 0.5 and 1.
        assert!((mcnemar_exact(2, 0).p_value - 0.5).abs() < 1e-15);
        assert_eq!(mcnemar_exact(1, 1).p_value, 1.0);
        assert_eq!(mcnemar_exact(0, 0).p_value, 1.0);
        // 8 to 2: 2 (1 + 10 + 45) / 1024 (scipy.stats.binomtest(2, 10): 0.109375).
        assert!((mcnemar_exact(8, 2).p_value - 0.109_375).abs() < 1e-12);
    }

    #[test]
    fn a_rate_seen_every_time_has_the_clopper_pearson_bound() {
        assert!((all_of_n_lower_bound(20, 0.05) - 0.860_891_659_331_734_8).abs() < 1e-12);
        assert_eq!(all_of_n_lower_bound(1, 0.05), 0.05);
        assert_eq!(all_of_n_lower_bound(0, 0.05), 0.0);
    }

    #[test]
    fn quantiles_interpolate_and_keep_infinities() {
        let v = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(quantile(&v, 0.5), 2.5);
        assert_eq!(quantile(&v, 0.25), 1.75);
        assert_eq!(quantile(&[1.0, f64::INFINITY], 1.0), f64::INFINITY);
        assert!(quantile(&[], 0.5).is_nan());
    }

    #[test]
    fn median_interval_uses_the_binomial_ranks() {
        let v: Vec<f64> = (1..=20).map(f64::from).collect();
        let ci = median_interval(&v).unwrap();
        // n = 20: P(B ≤ 5) = 0.0207, P(B ≤ 6) = 0.0577 → ranks 6 and 15.
        assert_eq!((ci.k, ci.low, ci.high), (6, 6.0, 15.0));
        assert!((ci.coverage - 0.958_610_5).abs() < 1e-6, "{}", ci.coverage);
        // Too few values for 95 %: the whole range, with its coverage.
        let ci = median_interval(&[1.0, 2.0, 3.0, 4.0, 5.0]).unwrap();
        assert_eq!((ci.low, ci.high, ci.coverage), (1.0, 5.0, 1.0 - 2.0 / 32.0));
    }

    /// The exact p-value against a brute-force count over every sign pattern.
    fn brute_p(d: &[f64]) -> f64 {
        let nz: Vec<f64> = d.iter().copied().filter(|x| *x != 0.0).collect();
        let r = mid_ranks(&nz);
        let w: f64 = nz
            .iter()
            .zip(&r)
            .filter(|(d, _)| **d > 0.0)
            .map(|(_, r)| r)
            .sum();
        let n = nz.len();
        let (mut le, mut ge) = (0u32, 0u32);
        for mask in 0..(1u32 << n) {
            let s: f64 = (0..n).filter(|i| mask >> i & 1 == 1).map(|i| r[i]).sum();
            le += u32::from(s <= w + 1e-9);
            ge += u32::from(s >= w - 1e-9);
        }
        (2.0 * f64::from(le.min(ge)) / f64::from(1u32 << n)).min(1.0)
    }

    #[test]
    fn signed_rank_matches_a_brute_force_count() {
        let a = [1.0, 2.5, 3.0, 0.5, 7.0, 2.0, 2.0, 9.0, 4.0, 1.0];
        let b = [0.0, 3.0, 1.0, 0.5, 4.0, 1.0, 3.0, 1.0, 4.5, 2.0];
        let d: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
        let t = signed_rank(&a, &b);
        assert_eq!((t.pairs, t.ties, t.a_smaller, t.b_smaller), (10, 1, 4, 5));
        assert!((t.p_value - brute_p(&d)).abs() < 1e-12, "{t:?}");
        // Every pair one way: p = 2 / 2^n.
        let t = signed_rank(&[2.0; 5], &[1.0, 1.5, 0.0, -1.0, 1.9]);
        assert_eq!((t.w_plus, t.p_value), (15.0, 2.0 / 32.0));
    }

    #[test]
    fn failed_runs_rank_as_the_largest_differences() {
        let inf = f64::INFINITY;
        let t = signed_rank(&[1.0, 1.0, 1.0, inf], &[inf, inf, inf, inf]);
        assert_eq!((t.ties, t.a_smaller, t.median_difference), (1, 3, -inf));
        assert_eq!(t.p_value, 2.0 / 8.0);
    }

    #[test]
    fn the_normal_approximation_agrees_with_the_exact_p() {
        let a: Vec<f64> = (0..150).map(|i| f64::from(i) * 0.37 % 5.0).collect();
        let b: Vec<f64> = (0..150).map(|i| f64::from(i) * 0.91 % 4.3).collect();
        let d: Vec<f64> = a
            .iter()
            .zip(&b)
            .map(|(x, y)| x - y)
            .filter(|x| *x != 0.0)
            .collect();
        let r = mid_ranks(&d);
        let w: f64 = d
            .iter()
            .zip(&r)
            .filter(|(d, _)| **d > 0.0)
            .map(|(_, r)| r)
            .sum();
        let (e, n) = (exact_p(&r, w), normal_p(&r, w));
        assert!((e - n).abs() < 0.01, "exact {e}, normal {n}");
    }
}
