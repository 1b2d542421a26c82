//! A spectral smoothness figure of the torque, per joint: CAPS's
//! (Mysore et al. 2021, "Regularizing action policies for smooth control
//! with reinforcement learning", eq. 8) amplitude-weighted mean
//! frequency, Sm = 2 / (n f_s) · Σ_{i=1}^{n} M_i f_i, over the n bins of
//! the torque's amplitude spectrum above 0 Hz (M_i = |X_i| / L of a
//! segment of L samples, f_i = i f_s / L, f_s = 1/Δt), in N m. Zero for a
//! constant torque; a torque that steps at every decision scores far above
//! one that ramps between the same values.
//!
//! The spectrum is averaged over consecutive segments of [`SEGMENT`]
//! steps (Welch's method with no window or overlap), so a run of any
//! length is summed in fixed memory; a run shorter than one segment is one
//! segment of its own length, and the steps after the last whole segment
//! of a longer run are left out.

use std::sync::Arc;

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

/// Steps per segment: 1.024 s at 1 kHz, bins 0.98 Hz apart.
pub const SEGMENT: usize = 1024;

/// Sums the torque's amplitude spectra, segment by segment.
#[derive(Clone)]
pub struct SmoothnessBuilder {
    dt: f64,
    /// The current segment's torques, joint by joint.
    segment: Vec<Vec<f64>>,
    /// Σ over whole segments of Σ_i M_i f_i, per joint.
    weighted: Vec<f64>,
    /// Σ over whole segments of n f_s (the figure's normaliser).
    norm: f64,
    fft: Arc<dyn Fft<f64>>,
    buffer: Vec<Complex<f64>>,
}

impl std::fmt::Debug for SmoothnessBuilder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SmoothnessBuilder")
            .field("dt", &self.dt)
            .field("weighted", &self.weighted)
            .field("norm", &self.norm)
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
            norm: 0.0,
            fft: FftPlanner::new().plan_fft_forward(SEGMENT),
            buffer: vec![Complex::default(); SEGMENT],
        }
    }

    /// Adds one step's torques (one per joint).
    pub fn add(&mut self, tau: &[f64]) {
        for (s, t) in self.segment.iter_mut().zip(tau) {
            s.push(*t);
        }
        if self.segment.first().is_some_and(|s| s.len() == SEGMENT) {
            let fft = Arc::clone(&self.fft);
            self.close_segment(fft.as_ref());
        }
    }

    /// Sm per joint over the steps added so far, N m (None before a step).
    pub fn finish(&self) -> Vec<Option<f64>> {
        let pending = self.segment.first().map_or(0, Vec::len);
        if self.norm > 0.0 {
            return self.weighted.iter().map(|w| Some(w / self.norm)).collect();
        }
        if pending == 0 {
            return vec![None; self.weighted.len()];
        }
        // Shorter than a segment: the run is one segment of its length.
        let mut short = self.clone();
        let fft = FftPlanner::new().plan_fft_forward(pending);
        short.close_segment(fft.as_ref());
        short
            .weighted
            .iter()
            .map(|w| Some(w / short.norm))
            .collect()
    }

    /// Adds the current segment's Σ_i M_i f_i per joint, and empties it.
    fn close_segment(&mut self, fft: &dyn Fft<f64>) {
        let len = fft.len();
        let fs = 1.0 / self.dt;
        let bins = len / 2;
        self.buffer.resize(len, Complex::default());
        for (s, w) in self.segment.iter_mut().zip(&mut self.weighted) {
            for (b, x) in self.buffer.iter_mut().zip(s.iter()) {
                *b = Complex::new(*x, 0.0);
            }
            fft.process(&mut self.buffer[..len]);
            *w += (1..=bins)
                .map(|i| self.buffer[i].norm() / len as f64 * (i as f64 * fs / len as f64))
                .sum::<f64>();
            s.clear();
        }
        // 2 / (n f_s) per segment; a sum of segments is their mean.
        self.norm += bins as f64 * fs / 2.0;
    }
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
    fn a_constant_torque_scores_zero_and_nothing_scores_none() {
        assert_eq!(sm((0..3000).map(|_| 5.0), 0.001), 0.0);
        assert_eq!(SmoothnessBuilder::new(2, 0.001).finish(), [None, None]);
    }

    #[test]
    fn a_sine_scores_its_amplitude_times_its_frequency_over_the_nyquist_rate() {
        // A sine of amplitude A at f on a bin: M = A/2 there, so Sm =
        // 2/(n f_s) · A/2 · f = A f / (n f_s) with n = L/2.
        let (a, dt) = (3.0, 0.001);
        let f = 64.0 / (SEGMENT as f64 * dt);
        let got = sm(
            (0..2 * SEGMENT).map(|k| a * (std::f64::consts::TAU * f * k as f64 * dt).sin()),
            dt,
        );
        let want = a * f / ((SEGMENT / 2) as f64 / dt);
        assert!((got - want).abs() < 1e-9 * want, "{got} against {want}");
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
    fn a_short_run_is_one_segment_of_its_length() {
        let got = sm(
            (0..100usize).map(|k| if k.is_multiple_of(2) { 1.0 } else { -1.0 }),
            0.001,
        );
        // All at the Nyquist bin: M = 1 at f_s/2, n = 50.
        assert!((got - 2.0 / (50.0 * 1000.0) * 500.0).abs() < 1e-12, "{got}");
    }
}
