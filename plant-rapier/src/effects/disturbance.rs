//! The bounded disturbance d(t) of the paper's eq. 1: constant + step +
//! sinusoid + band-limited noise, per joint.

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::PlantError;
use crate::config::DisturbanceConfig;

pub(crate) struct Disturbance {
    constant: Vec<f64>,
    step: Vec<f64>,
    step_at_s: f64,
    sin_amplitude: Vec<f64>,
    sin_omega: f64,
    noise_std: Vec<f64>,
    /// Per-period pole of the first-order noise filter.
    pole: f64,
    noise: Vec<f64>,
    rng: ChaCha8Rng,
    started: bool,
    out: Vec<f64>,
    on: bool,
}

impl Disturbance {
    pub(crate) fn new(
        c: &DisturbanceConfig,
        n: usize,
        dt: f64,
        rng: ChaCha8Rng,
    ) -> Result<Self, PlantError> {
        let constant = c.constant.resolve_signed("plant.disturbance.constant", n)?;
        let step = c.step.resolve_signed("plant.disturbance.step", n)?;
        let sin_amplitude = c
            .sin_amplitude
            .resolve_signed("plant.disturbance.sin_amplitude", n)?;
        let noise_std = c.noise_std.resolve("plant.disturbance.noise_std", n)?;
        let on = [&constant, &step, &sin_amplitude, &noise_std]
            .iter()
            .any(|v| v.iter().any(|x| *x != 0.0));
        Ok(Self {
            constant,
            step,
            step_at_s: c.step_at_s,
            sin_amplitude,
            sin_omega: c.sin_omega,
            noise_std,
            pole: (-std::f64::consts::TAU * c.noise_bandwidth_hz * dt).exp(),
            noise: vec![0.0; n],
            rng,
            started: false,
            out: vec![0.0; n],
            on,
        })
    }

    /// d at the start of the next period, t seconds; called once per period.
    pub(crate) fn advance(&mut self, t: f64) -> &[f64] {
        if !self.on {
            return &self.out;
        }
        // x ← a x + √(1−a²) σ w keeps the stationary std at σ; the first
        // value is drawn from that stationary law.
        let (a, b) = if self.started {
            (self.pole, (1.0 - self.pole * self.pole).sqrt())
        } else {
            (0.0, 1.0)
        };
        self.started = true;
        for i in 0..self.out.len() {
            let mut d = self.constant[i] + self.sin_amplitude[i] * (self.sin_omega * t).sin();
            if t >= self.step_at_s {
                d += self.step[i];
            }
            let s = self.noise_std[i];
            if s > 0.0 {
                let w: f64 = StandardNormal.sample(&mut self.rng);
                self.noise[i] = a * self.noise[i] + b * s * w;
                d += self.noise[i].clamp(-3.0 * s, 3.0 * s);
            }
            self.out[i] = d;
        }
        &self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PerJoint;
    use crate::effects::stream;

    fn config(f: impl FnOnce(&mut DisturbanceConfig)) -> DisturbanceConfig {
        let mut c = DisturbanceConfig::default();
        f(&mut c);
        c
    }

    #[test]
    fn deterministic_parts_follow_their_formulas() {
        let c = config(|c| {
            c.constant = PerJoint::Each(vec![1.0, -2.0]);
            c.step = PerJoint::All(0.5);
            c.step_at_s = 1.0;
            c.sin_amplitude = PerJoint::Each(vec![0.0, 3.0]);
            c.sin_omega = 2.0;
        });
        let mut d = Disturbance::new(&c, 2, 1e-3, stream(0, 2)).unwrap();
        assert_eq!(d.advance(0.5), [1.0, -2.0 + 3.0 * 1.0f64.sin()]);
        assert_eq!(d.advance(1.0), [1.5, -1.5 + 3.0 * 2.0f64.sin()]);
    }

    #[test]
    fn noise_is_bounded_and_has_the_set_std() {
        let c = config(|c| {
            c.noise_std = PerJoint::All(2.0);
            c.noise_bandwidth_hz = 50.0;
        });
        let mut d = Disturbance::new(&c, 1, 1e-3, stream(5, 2)).unwrap();
        let xs: Vec<f64> = (0..200_000)
            .map(|k| d.advance(k as f64 * 1e-3)[0])
            .collect();
        assert!(xs.iter().all(|x| x.abs() <= 6.0));
        let std = (xs.iter().map(|x| x * x).sum::<f64>() / xs.len() as f64).sqrt();
        // Correlated samples (τ ≈ 3 ms): 200 s is ~30 000 independent ones;
        // clipping at 3σ removes 1.3 % of the variance.
        assert!((std / 2.0 - 1.0).abs() < 0.03, "{std}");
        // Band-limited: neighbouring samples are strongly correlated.
        let lag1 = xs.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (xs.len() as f64 * std * std);
        let pole = (-std::f64::consts::TAU * 50.0 * 1e-3f64).exp();
        assert!((lag1 - pole).abs() < 0.03, "{lag1} vs {pole}");
    }
}
