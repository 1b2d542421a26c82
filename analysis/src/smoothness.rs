//! A spectral smoothness figure of the torque, per joint: CAPS's
//! (Mysore et al. 2021, "Regularizing action policies for smooth control
//! with reinforcement learning", eq. 8) amplitude-weighted mean
//! frequency, Sm = 2 / (n f_s) · Σ_{i=1}^{n} M_i f_i, over the n bins of
//! the torque's amplitude spectrum above 0 Hz, in N m. Zero for a torque
//! that is constant (or a straight line); a torque that steps at every
//! decision scores far above one that ramps between the same values.
//!
//! The spectrum is taken over consecutive segments of [`SEGMENT`] steps,
//! each with its straight-line trend removed and a Hann window applied
//! (without both, a slow swing of the torque shows as a jump where the
//! segment wraps, and that jump's spectrum reaches every bin): M_i =
//! |X_i| / Σ_k w_k, f_i = i f_s / L for a segment of L samples, f_s = 1/Δt.
//! The figure is the mean of the segments' Sm weighted by their length;
//! the steps after the last whole segment are a shorter segment of their
//! own, and a run (or a tail) of fewer than [`MIN_SEGMENT`] steps is left
//! out. So a run of any length is summed in fixed memory.

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

/// Steps per segment: 1.024 s at 1 kHz, bins 0.98 Hz apart.
pub const SEGMENT: usize = 1024;

/// The fewest steps a segment (a short run, or a run's tail) is taken of.
pub const MIN_SEGMENT: usize = 16;

/// Sums the torque's segment spectra.
#[derive(Clone)]
pub struct SmoothnessBuilder {
    dt: f64,
    /// The current segment's torques, joint by joint.
    segment: Vec<Vec<f64>>,
    /// Σ over closed segments of L · Sm, per joint.
    weighted: Vec<f64>,
    /// Σ over closed segments of L.
    steps: usize,
    planner: std::sync::Arc<dyn Fft<f64>>,
}

impl std::fmt::Debug for SmoothnessBuilder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SmoothnessBuilder")
            .field("dt", &self.dt)
            .field("weighted", &self.weighted)
            .field("steps", &self.steps)
            .finish_non_exhaustive()
    }
}

impl SmoothnessBuilder {
    /// For `n` joints at a period of `dt` s.
    pub fn new(n: usize, dt: f64) -> Self {
        Self {
            dt,
            segment: vec![Vec::with_capacity(SEGMENT); n],
            weighted: vec![0.0; n],
            steps: 0,
            planner: FftPlanner::new().plan_fft_forward(SEGMENT),
        }
    }

    /// Adds one step's torques (one per joint).
    pub fn add(&mut self, tau: &[f64]) {
        for (s, t) in self.segment.iter_mut().zip(tau) {
            s.push(*t);
        }
        if self.segment.first().is_some_and(|s| s.len() == SEGMENT) {
            let fft = std::sync::Arc::clone(&self.planner);
            self.close_segment(fft.as_ref());
        }
    }

    /// Sm per joint over the steps added so far, N m (None when fewer than
    /// [`MIN_SEGMENT`] steps were added).
    pub fn finish(&self) -> Vec<Option<f64>> {
        let pending = self.segment.first().map_or(0, Vec::len);
        let mut all = self.clone();
        if pending >= MIN_SEGMENT {
            let fft = FftPlanner::new().plan_fft_forward(pending);
            all.close_segment(fft.as_ref());
        }
        all.weighted
            .iter()
            .map(|w| (all.steps > 0).then(|| w / all.steps as f64))
            .collect()
    }

    /// Adds the current segment's L · Sm per joint, and empties it.
    fn close_segment(&mut self, fft: &dyn Fft<f64>) {
        let len = fft.len();
        let fs = 1.0 / self.dt;
        let bins = len / 2;
        let window: Vec<f64> = (0..len)
            .map(|k| 0.5 - 0.5 * (std::f64::consts::TAU * k as f64 / len as f64).cos())
            .collect();
        let gain: f64 = window.iter().sum();
        let mut buffer = vec![Complex::default(); len];
        for (s, w) in self.segment.iter_mut().zip(&mut self.weighted) {
            let (a, b) = line_fit(s);
            for (k, ((out, x), win)) in buffer.iter_mut().zip(s.iter()).zip(&window).enumerate() {
                *out = Complex::new((x - (a + b * k as f64)) * win, 0.0);
            }
            fft.process(&mut buffer);
            let sum: f64 = (1..=bins)
                .map(|i| buffer[i].norm() / gain * (i as f64 * fs / len as f64))
                .sum();
            *w += len as f64 * 2.0 / (bins as f64 * fs) * sum;
            s.clear();
        }
        self.steps += len;
    }
}

/// The least-squares line a + b k through `x` at k = 0, 1, ….
fn line_fit(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean_k = (n - 1.0) / 2.0;
    let mean_x = x.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (k, v) in x.iter().enumerate() {
        let dk = k as f64 - mean_k;
        sxy += dk * (v - mean_x);
        sxx += dk * dk;
    }
    let b = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    (mean_x - b * mean_k, b)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sm(samples: impl Iterator<Item = f64>, dt: f64) -> f64 {
        let mut b = SmoothnessBuilder::new(1, dt);
        for x in samples {
            b.add(&[x]);
        }
        b.finish()[0].unwrap_or(f64::NAN)
    }

    #[test]
    fn a_constant_or_straight_torque_scores_zero_and_too_few_steps_none() {
        assert!(sm((0..3000).map(|_| 5.0), 0.001).abs() < 1e-12);
        assert!(sm((0..3000).map(|k| 0.01 * k as f64), 0.001).abs() < 1e-9);
        assert_eq!(SmoothnessBuilder::new(2, 0.001).finish(), [None, None]);
        let mut b = SmoothnessBuilder::new(1, 0.001);
        b.add(&[1.0]);
        assert_eq!(b.finish(), [None]);
    }

    #[test]
    fn a_sine_scores_its_amplitude_times_its_frequency() {
        // On a bin, the Hann window puts A/2 there and A/4 on each side:
        // Σ M_i f_i = A f, so Sm = 2 A f / (n f_s) with n = L/2.
        let (a, dt) = (3.0, 0.001);
        let f = 64.0 / (SEGMENT as f64 * dt);
        let got = sm(
            (0..2 * SEGMENT).map(|k| a * (std::f64::consts::TAU * f * k as f64 * dt).sin()),
            dt,
        );
        let want = 2.0 * a * f / ((SEGMENT / 2) as f64 / dt);
        // To 0.1 %: the detrending takes out the sine's own slope too.
        assert!((got - want).abs() < 1e-3 * want, "{got} against {want}");
    }

    #[test]
    fn a_slow_swing_scores_far_below_a_small_chatter() {
        // 20 N m at 0.25 Hz against ±1 N m switching every 20 steps: the
        // window and the detrending keep the swing's wrap out of the bins.
        let swing = |k: usize| 20.0 * (std::f64::consts::TAU * 0.25 * k as f64 * 0.001).sin();
        let chatter = |k: usize| {
            if (k / 20).is_multiple_of(2) {
                1.0
            } else {
                -1.0
            }
        };
        let (s, c) = (
            sm((0..4000).map(swing), 0.001),
            sm((0..4000).map(chatter), 0.001),
        );
        assert!(s < 0.05 * c, "swing {s}, chatter {c}");
        let both = sm((0..4000).map(|k| swing(k) + chatter(k)), 0.001);
        assert!((both - c).abs() < 0.1 * c, "both {both}, chatter {c}");
    }

    #[test]
    fn steps_every_20_periods_score_above_a_ramp_between_the_same_values() {
        let held = |k: usize| {
            if (k / 20).is_multiple_of(2) {
                1.0
            } else {
                -1.0
            }
        };
        let ramp = |k: usize| {
            let (from, to) = (held(k.saturating_sub(20)), held(k));
            from + (to - from) * ((k % 20) + 1) as f64 / 20.0
        };
        let (h, r) = (
            sm((0..4000).map(held), 0.001),
            sm((0..4000).map(ramp), 0.001),
        );
        assert!(h > 1.5 * r, "held {h}, ramped {r}");
    }

    #[test]
    fn the_tail_counts_as_a_segment_of_its_own() {
        // Chatter only in the last 900 steps of 2948: without the tail the
        // figure would be zero.
        let got = sm(
            (0..2948).map(|k| if k >= 2048 && k % 2 == 0 { 1.0 } else { 0.0 }),
            0.001,
        );
        assert!(got > 0.0, "{got}");
    }
}
