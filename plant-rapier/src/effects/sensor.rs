//! What the joint sensors report: the true state plus Gaussian noise, with
//! q rounded to the encoder's resolution.

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

pub(crate) struct Sensor {
    q_std: Vec<f64>,
    qd_std: Vec<f64>,
    resolution: Vec<f64>,
    rng: ChaCha8Rng,
}

impl Sensor {
    pub(crate) fn new(
        q_std: Vec<f64>,
        qd_std: Vec<f64>,
        resolution: Vec<f64>,
        rng: ChaCha8Rng,
    ) -> Self {
        Self {
            q_std,
            qd_std,
            resolution,
            rng,
        }
    }

    /// Turns the true state in `q`, `qd` into the reading, in place.
    pub(crate) fn read(&mut self, q: &mut [f64], qd: &mut [f64]) {
        for i in 0..q.len() {
            if self.q_std[i] > 0.0 {
                let w: f64 = StandardNormal.sample(&mut self.rng);
                q[i] += self.q_std[i] * w;
            }
            if self.resolution[i] > 0.0 {
                q[i] = (q[i] / self.resolution[i]).round() * self.resolution[i];
            }
            if self.qd_std[i] > 0.0 {
                let w: f64 = StandardNormal.sample(&mut self.rng);
                qd[i] += self.qd_std[i] * w;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::stream;

    #[test]
    fn noise_has_the_set_standard_deviation() {
        let mut s = Sensor::new(vec![0.01, 0.0], vec![0.0, 0.2], vec![0.0; 2], stream(1, 1));
        let n = 50_000;
        let (mut sq, mut sqd, mut mean) = (0.0, 0.0, 0.0);
        for _ in 0..n {
            let (mut q, mut qd) = ([1.0, 2.0], [0.0, 0.0]);
            s.read(&mut q, &mut qd);
            assert_eq!(q[1], 2.0, "a joint without noise is exact");
            assert_eq!(qd[0], 0.0);
            mean += q[0] - 1.0;
            sq += (q[0] - 1.0).powi(2);
            sqd += qd[1].powi(2);
        }
        let nf = f64::from(n);
        // The sample std of 50 000 draws is within 1 % of σ with overwhelming odds.
        assert!(((sq / nf).sqrt() / 0.01 - 1.0).abs() < 0.01);
        assert!(((sqd / nf).sqrt() / 0.2 - 1.0).abs() < 0.01);
        assert!((mean / nf).abs() < 0.01 * 4.0 / nf.sqrt());
    }

    #[test]
    fn quantisation_rounds_to_the_resolution() {
        let res = std::f64::consts::TAU / 4096.0;
        let mut s = Sensor::new(vec![0.0], vec![0.0], vec![res], stream(0, 1));
        for x in [0.0, 0.3, -1.234_567, 2.0 * res + 0.49 * res] {
            let (mut q, mut qd) = ([x], [0.5]);
            s.read(&mut q, &mut qd);
            let counts = q[0] / res;
            assert!((counts - counts.round()).abs() < 1e-9, "{x}: {counts}");
            assert!((q[0] - x).abs() <= res / 2.0 + 1e-15);
            assert_eq!(qd[0], 0.5);
        }
    }
}
