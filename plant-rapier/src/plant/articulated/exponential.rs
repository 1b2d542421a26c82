//! URDF viscous damping integrated exactly: exponential time differencing
//! (ETDRK4, Cox & Matthews 2002) on the velocity, with the damping's linear
//! part −M₀⁻¹D q̇ (M₀ the inertia at the start of the step) solved in closed
//! form and everything else (gravity, Coriolis, the motors, the change of M
//! within the step) explicit as in RK4.
//!
//! Why: explicit RK4 is stable only while h·λmax(M⁻¹D) ≲ 2.8, and a damped
//! near-massless link has λ in the thousands to millions per second, which
//! cost 3.5–18× the substeps. Here every damped mode decays by its exact
//! factor e^(−λh) at any h, and a constant forcing reaches its exact steady
//! velocity, so one step per period stays stable and accurate. With no
//! damping the weights are RK4's: the engine keeps plain RK4 for such arms.
//!
//! M₀⁻¹D is diagonalised through the symmetric S = L⁻¹ D L⁻ᵀ (M₀ = L Lᵀ):
//! S = V Λ Vᵀ gives M₀⁻¹D = W Λ W⁻¹ with W = L⁻ᵀ V and W⁻¹ = Vᵀ Lᵀ, so each
//! mode is a scalar ODE and the matrix functions are per-eigenvalue weights.

use nalgebra::{DMatrix, SymmetricEigen};

use super::linalg::Cholesky;

/// The scalar weights of one step for a mode decaying at rate λ (z = −λh),
/// from φ_k(z) = Σ_j z^j/(j+k)! (φ_0 = e^z).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Weights {
    /// e^z.
    pub(super) e: f64,
    /// e^(z/2).
    pub(super) e2: f64,
    /// (h/2) φ1(z/2): a half step's response to a constant forcing.
    pub(super) half: f64,
    /// h (φ1 − 3φ2 + 4φ3): the velocity's weight of the first stage.
    pub(super) f1: f64,
    /// h (φ2 − 2φ3): of each middle stage.
    pub(super) f2: f64,
    /// h (4φ3 − φ2): of the last stage.
    pub(super) f3: f64,
    /// h φ1: the position's weight of the starting velocity.
    pub(super) p0: f64,
    /// h² (φ2 − 3φ3 + 4φ4): the position's weight of the first stage.
    pub(super) p1: f64,
    /// h² (2φ3 − 4φ4): of each middle stage.
    pub(super) p2: f64,
    /// h² (4φ4 − φ3): of the last stage.
    pub(super) p3: f64,
    /// φ1(z): the velocity a constant torque over the step leaves, per its
    /// impulse (1 undamped).
    pub(super) phi1: f64,
    /// φ2(z): the displacement it leaves, per impulse and step (½ undamped).
    pub(super) phi2: f64,
}

impl Weights {
    /// The weights for rate `lambda` ≥ 0 over `h`. The velocity's are
    /// Cox & Matthews'; the position's integrate the same forcing (their
    /// quadratic in time) once more, exactly, so a stiff mode's transient
    /// moves the joint by what it really does. At z = 0 both are RK4's.
    pub(super) fn new(lambda: f64, h: f64) -> Self {
        let z = -lambda.max(0.0) * h;
        let [_, p1, p2, p3, p4] = phi(z);
        let [_, half, ..] = phi(0.5 * z);
        Self {
            e: z.exp(),
            e2: (0.5 * z).exp(),
            half: 0.5 * h * half,
            f1: h * (p1 - 3.0 * p2 + 4.0 * p3),
            f2: h * (p2 - 2.0 * p3),
            f3: h * (4.0 * p3 - p2),
            p0: h * p1,
            p1: h * h * (p2 - 3.0 * p3 + 4.0 * p4),
            p2: h * h * (2.0 * p3 - 4.0 * p4),
            p3: h * h * (4.0 * p4 - p3),
            phi1: p1,
            phi2: p2,
        }
    }
}

/// φ_0..φ_4 at z ≤ 0. Near 0 the recurrence φ_(k+1) = (φ_k − 1/k!)/z
/// cancels catastrophically, so there φ4's series is summed (to a term
/// under 1e-18, at most 30) and the others follow downwards; beyond
/// |z| = 2, the upward recurrence loses under a digit a level.
pub(super) fn phi(z: f64) -> [f64; 5] {
    let mut out = [0.0; 5];
    if z.abs() < 2.0 {
        // φ4 = Σ_j z^j / (j+4)! term by term, then down by
        // φ_k = 1/k! + z φ_(k+1), which does not cancel for |z| < 2.
        let mut term = 1.0 / 24.0;
        for j in 0..30 {
            out[4] += term;
            term *= z / (j + 5) as f64;
            if term.abs() < 1e-18 {
                out[4] += term;
                break;
            }
        }
        let mut fact = 6.0;
        for k in (0..4).rev() {
            out[k] = 1.0 / fact + z * out[k + 1];
            fact /= k.max(1) as f64;
        }
    } else {
        out[0] = z.exp();
        let mut fact = 1.0;
        for k in 0..4 {
            out[k + 1] = (out[k] - 1.0 / fact) / z;
            fact *= (k + 1) as f64;
        }
    }
    out
}

/// tr(M⁻¹D) = Σ_j d_j ‖L⁻¹ e_j‖² for the factored M = L Lᵀ and the
/// diagonal damping `d`: an upper bound on M⁻¹D's largest rate (its
/// eigenvalues are those of L⁻¹ D L⁻ᵀ, all ≥ 0). L⁻¹ e_j is zero above
/// row j, so each column costs (n − j)² / 2. `x` is scratch of length n.
pub(super) fn damping_trace(chol: &Cholesky, d: &[f64], x: &mut [f64]) -> f64 {
    let n = d.len();
    let mut trace = 0.0;
    for (j, &dj) in d.iter().enumerate() {
        if dj <= 0.0 {
            continue;
        }
        let mut sq = 0.0;
        for i in j..n {
            let start = if i == j { 1.0 } else { 0.0 };
            let s = (j..i).fold(start, |s, k| s - chol.lower(i, k) * x[k]);
            x[i] = s / chol.lower(i, i);
            sq += x[i] * x[i];
        }
        trace += dj * sq;
    }
    trace
}

/// The damping's modes at the start of a step, and the stage buffers.
#[derive(Debug, Clone)]
pub(super) struct Modes {
    n: usize,
    /// W (row-major): a mode's coordinates → joint velocities.
    w: Vec<f64>,
    /// W⁻¹ (row-major): joint velocities → the modes' coordinates.
    w_inv: Vec<f64>,
    /// The weights per mode for the step size last used.
    pub(super) weights: Vec<Weights>,
    /// Decay rates λ_i, 1/s.
    rates: Vec<f64>,
    col: Vec<f64>,
    s: DMatrix<f64>,
}

impl Modes {
    pub(super) fn new(n: usize) -> Self {
        Self {
            n,
            w: vec![0.0; n * n],
            w_inv: vec![0.0; n * n],
            weights: vec![Weights::new(0.0, 0.0); n],
            rates: vec![0.0; n],
            col: vec![0.0; n],
            s: DMatrix::zeros(n, n),
        }
    }

    /// The modes of M₀⁻¹D for the factored M₀ = L Lᵀ in `chol` and the
    /// diagonal damping `d` (≥ 0), with the weights for step `h`.
    pub(super) fn update(&mut self, chol: &Cholesky, d: &[f64], h: f64) {
        let n = self.n;
        // B = L⁻¹ √D column by column; S = B Bᵀ.
        let mut b = vec![0.0; n * n];
        for j in 0..n {
            self.col.iter_mut().for_each(|x| *x = 0.0);
            self.col[j] = d[j].max(0.0).sqrt();
            chol.forward(&mut self.col);
            for i in 0..n {
                b[i * n + j] = self.col[i];
            }
        }
        for i in 0..n {
            for j in 0..=i {
                let v: f64 = (0..n).map(|k| b[i * n + k] * b[j * n + k]).sum();
                self.s[(i, j)] = v;
                self.s[(j, i)] = v;
            }
        }
        let eig = SymmetricEigen::new(self.s.clone());
        for m in 0..n {
            // W's column m = L⁻ᵀ v_m.
            for i in 0..n {
                self.col[i] = eig.eigenvectors[(i, m)];
            }
            chol.backward(&mut self.col);
            for i in 0..n {
                self.w[i * n + m] = self.col[i];
            }
            // W⁻¹'s row m = v_mᵀ Lᵀ, i.e. (L v_m)ᵀ.
            for i in 0..n {
                self.w_inv[m * n + i] = (0..=i)
                    .map(|k| chol.lower(i, k) * eig.eigenvectors[(k, m)])
                    .sum();
            }
            // Rounding can leave a zero rate slightly negative.
            self.rates[m] = eig.eigenvalues[m].max(0.0);
            self.weights[m] = Weights::new(self.rates[m], h);
        }
    }

    /// Decay rate of mode `m`.
    pub(super) fn rate(&self, m: usize) -> f64 {
        self.rates[m]
    }

    /// out = W diag(φ(w_m)) Wᵀ x: with φ1, the velocity a constant torque
    /// whose impulse over the step is x leaves (M₀⁻¹ x undamped; W Wᵀ =
    /// M₀⁻¹); with φ2, its displacement per step.
    /// `tmp` is scratch of length n.
    pub(super) fn response(
        &self,
        phi: fn(&Weights) -> f64,
        x: &[f64],
        tmp: &mut [f64],
        out: &mut [f64],
    ) {
        let n = self.n;
        for (m, c) in tmp.iter_mut().enumerate() {
            let wt_x: f64 = (0..n).map(|i| self.w[i * n + m] * x[i]).sum();
            *c = phi(&self.weights[m]) * wt_x;
        }
        mul(&self.w, n, tmp, out);
    }

    /// out (row-major, symmetric) = W diag(φ(w_m)) Wᵀ: column j is
    /// [`Self::response`] to e_j, made in one pass (half the work).
    pub(super) fn response_matrix(&self, phi: fn(&Weights) -> f64, out: &mut [f64]) {
        let n = self.n;
        for i in 0..n {
            let wi = &self.w[i * n..(i + 1) * n];
            for j in 0..=i {
                let wj = &self.w[j * n..(j + 1) * n];
                let v: f64 = (0..n).map(|m| wi[m] * phi(&self.weights[m]) * wj[m]).sum();
                out[i * n + j] = v;
                out[j * n + i] = v;
            }
        }
    }

    /// y = W⁻¹ v.
    pub(super) fn to_modes(&self, v: &[f64], y: &mut [f64]) {
        mul(&self.w_inv, self.n, v, y);
    }

    /// v = W y.
    pub(super) fn to_joints(&self, y: &[f64], v: &mut [f64]) {
        mul(&self.w, self.n, y, v);
    }
}

fn mul(a: &[f64], n: usize, x: &[f64], out: &mut [f64]) {
    for (i, o) in out.iter_mut().enumerate().take(n) {
        *o = a[i * n..(i + 1) * n]
            .iter()
            .zip(x)
            .map(|(a, x)| a * x)
            .sum();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// φ's series and recurrence agree on both sides of the switch, and
    /// at z = 0 the weights are RK4's.
    #[test]
    fn weights_are_continuous_and_rk4_at_zero() {
        let w = Weights::new(0.0, 1.0);
        assert_eq!((w.e, w.e2), (1.0, 1.0));
        let sixth = 1.0 / 6.0;
        for (x, want) in [
            (w.half, 0.5),
            (w.f1, sixth),
            (w.f2, sixth),
            (w.f3, sixth),
            (w.p0, 1.0),
            (w.p1, sixth),
            (w.p2, sixth),
            (w.p3, 0.0),
        ] {
            assert!((x - want).abs() < 1e-15, "{x} vs {want}: {w:?}");
        }
        for z in [-1.999_999f64, -2.000_001, -2.5] {
            // The recurrence against the series summed directly.
            let series: Vec<f64> = (0..5)
                .map(|k| {
                    (0..60)
                        .map(|j| {
                            z.powi(j) / (1..=(j as usize + k)).map(|i| i as f64).product::<f64>()
                        })
                        .sum()
                })
                .collect();
            let got = phi(z);
            for k in 0..5 {
                assert!(
                    (got[k] - series[k]).abs() < 1e-13,
                    "φ{k}({z}): {} vs {}",
                    got[k],
                    series[k]
                );
            }
        }
    }

    /// W⁻¹ W = I and W Λ W⁻¹ = M⁻¹ D on a coupled inertia with one
    /// undamped, one mildly and one stiffly damped joint.
    #[test]
    fn the_modes_diagonalise_m_inverse_d() {
        let m = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 0.3];
        let d = [0.0, 2.0, 5e3];
        let mut chol = Cholesky::new(3);
        chol.matrix_mut().copy_from_slice(&m);
        chol.factor().unwrap_or_else(|row| panic!("row {row}"));
        let mut modes = Modes::new(3);
        modes.update(&chol, &d, 1e-3);
        for j in 0..3 {
            // Column j of M⁻¹ D, and of W Λ W⁻¹, and W W⁻¹ e_j.
            let mut want = [0.0; 3];
            want[j] = d[j];
            chol.solve(&mut want);
            let mut e = [0.0; 3];
            e[j] = 1.0;
            let (mut y, mut back) = ([0.0; 3], [0.0; 3]);
            modes.to_modes(&e, &mut y);
            modes.to_joints(&y, &mut back);
            y.iter_mut()
                .enumerate()
                .for_each(|(k, y)| *y *= modes.rate(k));
            let mut got = [0.0; 3];
            modes.to_joints(&y, &mut got);
            for i in 0..3 {
                assert!((back[i] - e[i]).abs() < 1e-12, "W W⁻¹ column {j}: {back:?}");
                assert!(
                    (got[i] - want[i]).abs() < 1e-9 * (1.0 + want[i].abs()),
                    "column {j}: {got:?} vs {want:?}"
                );
            }
        }
    }

    /// The response matrix's columns are the responses to unit impulses.
    #[test]
    fn response_matrix_columns_are_unit_responses() {
        let m = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 0.3];
        let mut chol = Cholesky::new(3);
        chol.matrix_mut().copy_from_slice(&m);
        chol.factor().unwrap_or_else(|row| panic!("row {row}"));
        let mut modes = Modes::new(3);
        modes.update(&chol, &[0.0, 2.0, 5e3], 1e-3);
        let mut all = [0.0; 9];
        modes.response_matrix(|w| w.phi1, &mut all);
        for j in 0..3 {
            let mut e = [0.0; 3];
            e[j] = 1.0;
            let (mut tmp, mut col) = ([0.0; 3], [0.0; 3]);
            modes.response(|w| w.phi1, &e, &mut tmp, &mut col);
            for i in 0..3 {
                assert!((all[i * 3 + j] - col[i]).abs() < 1e-12 * (1.0 + col[i].abs()));
            }
        }
    }

    /// tr(M⁻¹D) from the factor equals the trace of M⁻¹D computed whole.
    #[test]
    fn damping_trace_is_the_trace_of_m_inverse_d() {
        let m = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 0.3];
        let d = [0.0, 2.0, 5e3];
        let mut chol = Cholesky::new(3);
        chol.matrix_mut().copy_from_slice(&m);
        chol.factor().unwrap_or_else(|row| panic!("row {row}"));
        let mut want = 0.0;
        for j in 0..3 {
            let mut col = [0.0; 3];
            col[j] = d[j];
            chol.solve(&mut col);
            want += col[j];
        }
        let got = damping_trace(&chol, &d, &mut [0.0; 3]);
        assert!((got - want).abs() < 1e-12 * want, "{got} vs {want}");
    }

    /// A constant forcing f on v̇ = −λv + f over one step lands exactly on
    /// the exact velocity and position, at any λh (what lets a stiff mode
    /// take one step).
    #[test]
    fn a_constant_forcing_is_integrated_exactly() {
        for lambda in [0.0, 0.3, 7.0, 1e3, 1e6, 1e9] {
            let (h, v0, f) = (1e-3, 0.7, 2.0);
            let w = Weights::new(lambda, h);
            // N = f at every stage of ETDRK4's split.
            let v1 = w.e * v0 + (w.f1 + 4.0 * w.f2 + w.f3) * f;
            let dq = w.p0 * v0 + (w.p1 + 2.0 * w.p2 + w.p3) * f;
            let (v, q) = if lambda == 0.0 {
                (v0 + f * h, v0 * h + 0.5 * f * h * h)
            } else {
                let ss = f / lambda;
                let decay = (-lambda * h).exp();
                (
                    ss + (v0 - ss) * decay,
                    ss * h + (v0 - ss) * (1.0 - decay) / lambda,
                )
            };
            assert!(
                (v1 - v).abs() < 1e-12 * (1.0 + v.abs()),
                "λ {lambda}: v {v1} vs {v}"
            );
            assert!(
                (dq - q).abs() < 1e-12 * q.abs().max(1e-9),
                "λ {lambda}: Δq {dq} vs {q}"
            );
        }
    }
}
