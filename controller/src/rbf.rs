//! Gaussian radial-basis features (SPEC §8), in two centre layouts.

use crate::RbfLayout;

/// Gaussian neurons over an input of `dim` entries.
///
/// Diagonal (the paper's): N neurons S_j(x) = exp(-‖x - c_j 1‖² / η²).
/// Per input: N neurons per entry, S_{d,j}(x) = exp(-(x_d - c_j)² / η²),
/// feature index d·N + j. In both, c_j is evenly spaced over
/// [c_min, c_max], ends included.
#[derive(Debug, Clone)]
pub struct Rbf {
    layout: RbfLayout,
    dim: usize,
    centers: Vec<f64>,
    inv_width2: f64,
}

impl Rbf {
    /// `neurons` ≥ 1; one neuron sits at the middle of the range.
    pub fn new(
        layout: RbfLayout,
        neurons: usize,
        dim: usize,
        c_min: f64,
        c_max: f64,
        width: f64,
    ) -> Self {
        let centers = if neurons == 1 {
            vec![0.5 * (c_min + c_max)]
        } else {
            let step = (c_max - c_min) / (neurons - 1) as f64;
            (0..neurons).map(|j| c_min + step * j as f64).collect()
        };
        Self {
            layout,
            dim,
            centers,
            inv_width2: 1.0 / (width * width),
        }
    }

    /// Number of features: N, or N per input.
    pub fn len(&self) -> usize {
        match self.layout {
            RbfLayout::Diagonal => self.centers.len(),
            RbfLayout::PerInput => self.centers.len() * self.dim,
        }
    }

    /// Always false: a network has at least one neuron.
    pub fn is_empty(&self) -> bool {
        self.centers.is_empty()
    }

    /// The centre value c_j of each neuron (per input, for `PerInput`).
    pub fn centers(&self) -> &[f64] {
        &self.centers
    }

    /// S(x) into `out` (length [`Rbf::len`]).
    pub fn features(&self, x: &[f64], out: &mut [f64]) {
        match self.layout {
            RbfLayout::Diagonal => {
                for (s, &c) in out.iter_mut().zip(&self.centers) {
                    let d2: f64 = x.iter().map(|&xi| (xi - c) * (xi - c)).sum();
                    *s = (-d2 * self.inv_width2).exp();
                }
            }
            RbfLayout::PerInput => {
                let nn = self.centers.len();
                for (row, &xd) in out.chunks_exact_mut(nn).zip(x) {
                    for (s, &c) in row.iter_mut().zip(&self.centers) {
                        *s = (-(xd - c) * (xd - c) * self.inv_width2).exp();
                    }
                }
            }
        }
    }

    /// (∇S · ẋ) into `out`, given S = `features(x)`.
    pub fn directional_derivative(&self, x: &[f64], xdot: &[f64], s: &[f64], out: &mut [f64]) {
        match self.layout {
            RbfLayout::Diagonal => {
                for ((o, &sj), &c) in out.iter_mut().zip(s).zip(&self.centers) {
                    let proj: f64 = x.iter().zip(xdot).map(|(&xi, &vi)| (xi - c) * vi).sum();
                    *o = -2.0 * sj * proj * self.inv_width2;
                }
            }
            RbfLayout::PerInput => {
                let nn = self.centers.len();
                let rows = out.chunks_exact_mut(nn).zip(s.chunks_exact(nn));
                for ((row, srow), (&xd, &vd)) in rows.zip(x.iter().zip(xdot)) {
                    for ((o, &sj), &c) in row.iter_mut().zip(srow).zip(&self.centers) {
                        *o = -2.0 * sj * (xd - c) * vd * self.inv_width2;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_centres_are_evenly_spaced_with_ends() {
        let rbf = Rbf::new(RbfLayout::Diagonal, 10, 4, -5.0, 5.0, 1.0);
        assert_eq!(rbf.centers()[0], -5.0);
        assert_eq!(rbf.centers()[9], 5.0);
        let step = 10.0 / 9.0;
        for (j, c) in rbf.centers().iter().enumerate() {
            assert!((c - (-5.0 + step * j as f64)).abs() < 1e-14);
        }
    }

    #[test]
    fn features_by_hand() {
        let rbf = Rbf::new(RbfLayout::Diagonal, 3, 2, -1.0, 1.0, 2.0);
        let mut s = [0.0; 3];
        rbf.features(&[0.5, -0.5], &mut s);
        // ‖x - c1‖² for c = -1, 0, 1: 2.5, 0.5, 2.5; divided by η² = 4.
        assert!((s[0] - (-2.5f64 / 4.0).exp()).abs() < 1e-15);
        assert!((s[1] - (-0.5f64 / 4.0).exp()).abs() < 1e-15);
        assert!((s[2] - (-2.5f64 / 4.0).exp()).abs() < 1e-15);
    }

    #[test]
    fn directional_derivative_matches_finite_difference() {
        for layout in [RbfLayout::Diagonal, RbfLayout::PerInput] {
            derivative_by_difference(layout);
        }
    }

    #[test]
    fn per_input_features_by_hand() {
        let rbf = Rbf::new(RbfLayout::PerInput, 3, 2, -1.0, 1.0, 2.0);
        assert_eq!(rbf.len(), 6);
        let mut s = [0.0; 6];
        rbf.features(&[0.5, -1.0], &mut s);
        let g = |d: f64| (-d * d / 4.0).exp();
        let want = [g(1.5), g(0.5), g(0.5), g(0.0), g(1.0), g(2.0)];
        for (a, b) in s.iter().zip(want) {
            assert!((a - b).abs() < 1e-15);
        }
    }

    fn derivative_by_difference(layout: RbfLayout) {
        let rbf = Rbf::new(layout, 10, 4, -5.0, 5.0, 1.0);
        let x = [0.3, -0.2, 0.8, 0.1];
        let v = [1.0, -2.0, 0.5, 3.0];
        let len = rbf.len();
        let (mut s, mut d, mut sp, mut sm) = (
            vec![0.0; len],
            vec![0.0; len],
            vec![0.0; len],
            vec![0.0; len],
        );
        rbf.features(&x, &mut s);
        rbf.directional_derivative(&x, &v, &s, &mut d);
        let h = 1e-6;
        let xp: Vec<f64> = x.iter().zip(&v).map(|(a, b)| a + h * b).collect();
        let xm: Vec<f64> = x.iter().zip(&v).map(|(a, b)| a - h * b).collect();
        rbf.features(&xp, &mut sp);
        rbf.features(&xm, &mut sm);
        for j in 0..len {
            let fd = (sp[j] - sm[j]) / (2.0 * h);
            assert!((d[j] - fd).abs() < 1e-8, "neuron {j}: {} vs {fd}", d[j]);
        }
    }
}
