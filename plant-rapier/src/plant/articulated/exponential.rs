//! URDF viscous damping integrated exactly where it is stiff: exponential
//! time differencing (ETDRK4, Cox & Matthews 2002) on the velocity, with
//! the stiff part of the damping's linear term −M₀⁻¹D_S q̇ (M₀ the inertia
//! at the start of the step) solved in closed form and everything else
//! (gravity, Coriolis, the motors, the mild rest of the damping, the
//! change of M within the step) explicit as in RK4.
//!
//! Why: explicit RK4 is stable only while h·λmax(M⁻¹D) ≲ 2.8, and a damped
//! near-massless link has λ in the thousands to millions per second, which
//! cost 3.5–18× the substeps. Here every stiff mode decays by its exact
//! factor e^(−λh) at any h, and a constant forcing reaches its exact steady
//! velocity, so one step per period stays stable and accurate. With no
//! damping the weights are RK4's: the engine keeps plain RK4 for such arms.
//!
//! Only the joints that carry the most of h·tr(M₀⁻¹D) are in S (see
//! [`Modes`]): M₀⁻¹D_S has rank |S|, so its modes come from an |S| × |S|
//! eigendecomposition, and every other direction is a mode of rate 0.

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

/// Largest h·tr(M⁻¹D) a step's explicit stages carry in any group of
/// joints that couple (M⁻¹D is block diagonal over the groups, so its
/// fastest rate λmax is the largest of the blocks', each at most the
/// block's trace). RK4's factor for that mode is then within 5e-4 of the
/// exact e^(−λh) (at λh = 0.5; far less below), and far inside its
/// stability limit of 2.8. A step whose damping is this mild in every
/// group is plain RK4; otherwise, in each group, the joints that carry the
/// most of its trace are solved in modes until the rest is this mild.
pub(super) const MILD_DAMPING: f64 = 0.5;

/// Per joint j, its share d_j (M⁻¹)_jj of tr(M⁻¹D) into `out`, for the
/// factored M and the diagonal damping `d`; returns the largest trace of
/// a group's block of M⁻¹D, an upper bound on M⁻¹D's largest rate (each
/// block's eigenvalues are ≥ 0, those of its L⁻¹ D L⁻ᵀ). `x` is scratch
/// of length n.
pub(super) fn damping_shares(chol: &Cholesky, d: &[f64], x: &mut [f64], out: &mut [f64]) -> f64 {
    for (j, (&dj, share)) in d.iter().zip(out.iter_mut()).enumerate() {
        *share = if dj > 0.0 {
            dj * chol.inverse_diagonal(j, x)
        } else {
            0.0
        };
    }
    group_traces(chol, out, x);
    x.iter().copied().fold(0.0, f64::max)
}

/// Per group label g, the sum of the shares of its joints into `out[g]`.
fn group_traces(chol: &Cholesky, shares: &[f64], out: &mut [f64]) {
    out.iter_mut().for_each(|x| *x = 0.0);
    for (j, share) in shares.iter().enumerate() {
        out[chol.group(j)] += share;
    }
}

/// The stiff damping's modes at the start of a step.
///
/// In each group of joints that couple, the joints whose shares of
/// h·tr(M₀⁻¹D) are largest, until the group's rest is at most
/// [`MILD_DAMPING`], form the stiff set S; their damping D_S is
/// solved exactly and the rest stays explicit. A = M₀⁻¹D_S has rank |S|:
/// with C = M₀⁻¹ √D_S and R = √D_S (S's rows), A = C R, and its non-zero
/// rates are the eigenvalues of the small G = R C = √D_S (M₀⁻¹)_SS √D_S
/// = U Λ Uᵀ. Mode m has w_m = C u_m / √λ_m and ŵ_m = Rᵀ u_m / √λ_m
/// (ŵ_mᵀ w_k = δ_mk); every direction ŵ-orthogonal to them has rate 0.
/// So a velocity's coordinates are the |S| modes' and, for that rest,
/// the velocity minus its modes' part, in joint coordinates; an arm of 30
/// joints with 4 stiff ones needs a 4 × 4 eigendecomposition, not 30 × 30.
#[derive(Debug, Clone)]
pub(super) struct Modes {
    n: usize,
    /// M₀'s factor, for the responses.
    m0: Cholesky,
    /// The stiff joints, and their √d.
    stiff: Vec<usize>,
    root_d: Vec<f64>,
    /// Kept modes: a rate under 1e-12 of its group's largest is left to
    /// the rest.
    r: usize,
    /// Mode m's w_m: `w[m * n + i]`.
    w: Vec<f64>,
    /// Mode m's ŵ_m on S: `w_hat[m * |S| + a]`.
    w_hat: Vec<f64>,
    rates: Vec<f64>,
    weights: Vec<Weights>,
    /// The weights at rate 0, for the rest.
    still: Weights,
    /// C's columns: `cols[a * n + i]`.
    cols: Vec<f64>,
    ranked: Vec<usize>,
    /// Per group label: its trace not yet in S.
    rest: Vec<f64>,
}

impl Modes {
    pub(super) fn new(m0: Cholesky, n: usize) -> Self {
        Self {
            n,
            m0,
            stiff: Vec::with_capacity(n),
            root_d: Vec::with_capacity(n),
            r: 0,
            w: vec![0.0; n * n],
            w_hat: vec![0.0; n * n],
            rates: vec![0.0; n],
            weights: vec![Weights::new(0.0, 0.0); n],
            still: Weights::new(0.0, 0.0),
            cols: vec![0.0; n * n],
            ranked: Vec::with_capacity(n),
            rest: vec![0.0; n],
        }
    }

    /// The modes for the factored M₀ in `chol`, the diagonal damping `d`
    /// (≥ 0) and its `shares` (from [`damping_shares`]), with the weights
    /// for step `h`. False where there are none to make: a state blown up
    /// so far that G is not finite, or (never seen) an eigenproblem that
    /// does not converge.
    #[must_use]
    pub(super) fn update(&mut self, chol: &Cholesky, d: &[f64], shares: &[f64], h: f64) -> bool {
        self.m0.copy_factor(chol);
        self.choose_stiff(chol, d, shares, h);
        let (n, s) = (self.n, self.stiff.len());
        for (a, &b) in self.stiff.iter().enumerate() {
            let col = &mut self.cols[a * n..(a + 1) * n];
            col.iter_mut().for_each(|x| *x = 0.0);
            col[b] = self.root_d[a];
            chol.solve(col);
        }
        // G is block diagonal over the joints' groups (the fixed root's
        // subtrees do not couple): one small eigenproblem per block.
        self.r = 0;
        let mut start = 0;
        while start < s {
            let group = chol.group(self.stiff[start]);
            let len = self.stiff[start..]
                .iter()
                .take_while(|&&j| chol.group(j) == group)
                .count();
            if !self.add_block(start, start + len, h) {
                return false;
            }
            start += len;
        }
        self.still = Weights::new(0.0, h);
        true
    }

    /// The modes of G's block over the stiff joints `from..to` (one group);
    /// false where G is not finite or its eigenproblem does not converge.
    fn add_block(&mut self, from: usize, to: usize, h: f64) -> bool {
        let (n, s) = (self.n, self.stiff.len());
        let g = DMatrix::from_fn(to - from, to - from, |a, b| {
            let (a, b) = (from + a, from + b);
            let ab = self.root_d[a] * self.cols[b * n + self.stiff[a]];
            let ba = self.root_d[b] * self.cols[a * n + self.stiff[b]];
            0.5 * (ab + ba)
        });
        if g.iter().any(|x| !x.is_finite()) {
            return false;
        }
        // A bound on the QR sweeps: nalgebra's default has none.
        let Some(eig) = SymmetricEigen::try_new(g, f64::EPSILON, 100 * (to - from) + 100) else {
            return false;
        };
        let top = eig.eigenvalues.iter().copied().fold(0.0, f64::max);
        for (m, &lambda) in eig.eigenvalues.iter().enumerate() {
            if lambda.is_nan() || lambda <= 1e-12 * top {
                continue;
            }
            let r = self.r;
            let scale = lambda.sqrt().recip();
            let u = eig.eigenvectors.column(m);
            let wr = &mut self.w[r * n..(r + 1) * n];
            wr.iter_mut().for_each(|x| *x = 0.0);
            for (b, col) in self.cols[from * n..to * n].chunks_exact(n).enumerate() {
                let c = u[b] * scale;
                for (x, v) in wr.iter_mut().zip(col) {
                    *x += c * v;
                }
            }
            let wh = &mut self.w_hat[r * s..(r + 1) * s];
            wh.iter_mut().for_each(|x| *x = 0.0);
            for a in from..to {
                wh[a] = self.root_d[a] * u[a - from] * scale;
            }
            self.rates[r] = lambda;
            self.weights[r] = Weights::new(lambda, h);
            self.r += 1;
        }
        true
    }

    /// S: in each group, the joints with the largest shares until the
    /// group's rest is mild; ordered by group.
    fn choose_stiff(&mut self, chol: &Cholesky, d: &[f64], shares: &[f64], h: f64) {
        self.ranked.clear();
        self.ranked.extend((0..self.n).filter(|&j| shares[j] > 0.0));
        self.ranked
            .sort_by(|&a, &b| shares[b].total_cmp(&shares[a]).then(a.cmp(&b)));
        let rest = &mut self.rest;
        group_traces(chol, shares, rest);
        self.stiff.clear();
        self.root_d.clear();
        for &j in &self.ranked {
            let g = chol.group(j);
            if h * rest[g] > MILD_DAMPING {
                rest[g] -= shares[j];
                self.stiff.push(j);
            }
        }
        self.stiff.sort_by_key(|&j| (chol.group(j), j));
        self.root_d.extend(self.stiff.iter().map(|&j| d[j].sqrt()));
    }

    /// The length of a velocity's coordinates: the modes, then the rest.
    pub(super) fn len(&self) -> usize {
        self.r + self.n
    }

    /// The weights of coordinate `m`.
    pub(super) fn weight(&self, m: usize) -> Weights {
        if m < self.r {
            self.weights[m]
        } else {
            self.still
        }
    }

    /// Decay rate of coordinate `m`.
    pub(super) fn rate(&self, m: usize) -> f64 {
        if m < self.r { self.rates[m] } else { 0.0 }
    }

    /// out = φ(A) M₀⁻¹ x = φ(0) M₀⁻¹ x + Σ_m (φ(λ_m) − φ(0)) w_m w_mᵀ x
    /// (ŵ_mᵀ M₀⁻¹ = w_mᵀ): with φ1, the velocity a constant torque whose
    /// impulse over the step is x leaves (M₀⁻¹ x undamped); with φ2, its
    /// displacement per step.
    pub(super) fn response(&self, phi: fn(&Weights) -> f64, x: &[f64], out: &mut [f64]) {
        let n = self.n;
        out.copy_from_slice(x);
        self.m0.solve(out);
        let p0 = phi(&self.still);
        out.iter_mut().for_each(|v| *v *= p0);
        for m in 0..self.r {
            let wm = &self.w[m * n..(m + 1) * n];
            let c = (phi(&self.weights[m]) - p0) * dot(wm, x);
            for (o, w) in out.iter_mut().zip(wm) {
                *o += c * w;
            }
        }
    }

    /// Columns `cols` of φ(A) M₀⁻¹ (symmetric) into `out` (row-major
    /// n × n, column j as row j; other rows untouched): column j is
    /// [`Self::response`] to e_j.
    pub(super) fn response_columns(
        &self,
        phi: fn(&Weights) -> f64,
        cols: &[usize],
        out: &mut [f64],
    ) {
        let n = self.n;
        self.m0.inverse_columns(cols, out);
        let p0 = phi(&self.still);
        for &j in cols {
            let col = &mut out[j * n..(j + 1) * n];
            col.iter_mut().for_each(|v| *v *= p0);
            for m in 0..self.r {
                let wm = &self.w[m * n..(m + 1) * n];
                let c = (phi(&self.weights[m]) - p0) * wm[j];
                for (o, w) in col.iter_mut().zip(wm) {
                    *o += c * w;
                }
            }
        }
    }

    /// The coordinates of v: y_m = ŵ_mᵀ v, then v − Σ_m w_m y_m.
    pub(super) fn to_modes(&self, v: &[f64], y: &mut [f64]) {
        let (n, r, s) = (self.n, self.r, self.stiff.len());
        for (ym, wh) in y[..r].iter_mut().zip(self.w_hat.chunks_exact(s.max(1))) {
            *ym = self.stiff.iter().zip(wh).map(|(&j, w)| w * v[j]).sum();
        }
        let (modes, rest) = y.split_at_mut(r);
        rest[..n].copy_from_slice(v);
        for (m, ym) in modes.iter().enumerate() {
            for (o, w) in rest[..n].iter_mut().zip(&self.w[m * n..(m + 1) * n]) {
                *o -= ym * w;
            }
        }
    }

    /// v = Σ_m w_m y_m + the rest.
    pub(super) fn to_joints(&self, y: &[f64], v: &mut [f64]) {
        let (n, r) = (self.n, self.r);
        v.copy_from_slice(&y[r..r + n]);
        for (m, ym) in y[..r].iter().enumerate() {
            for (o, w) in v.iter_mut().zip(&self.w[m * n..(m + 1) * n]) {
                *o += ym * w;
            }
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
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

    const M: [f64; 9] = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 0.3];
    const D: [f64; 3] = [0.0, 2.0, 5e3];

    fn modes_at(h: f64) -> (Cholesky, Modes) {
        let mut chol = Cholesky::new(3);
        chol.matrix_mut().copy_from_slice(&M);
        chol.factor().unwrap_or_else(|row| panic!("row {row}"));
        let mut shares = [0.0; 3];
        damping_shares(&chol, &D, &mut [0.0; 3], &mut shares);
        let mut modes = Modes::new(chol.clone(), 3);
        assert!(modes.update(&chol, &D, &shares, h));
        (chol, modes)
    }

    /// The coordinates go back to the same velocity, and A = W Λ Ŵᵀ is
    /// M⁻¹ D_S: at 1 ms only the stiff joint (h·share 17) is in S, the
    /// mild one (7e-4) stays explicit; at 1 s both are in S.
    #[test]
    fn the_modes_diagonalise_the_stiff_part_of_m_inverse_d() {
        for (h, stiff) in [(1e-3, [0.0, 0.0, D[2]]), (1.0, D)] {
            let (chol, modes) = modes_at(h);
            assert_eq!(modes.len(), 3 + stiff.iter().filter(|d| **d > 0.0).count());
            for j in 0..3 {
                let mut want = [0.0; 3];
                want[j] = stiff[j];
                chol.solve(&mut want);
                let mut e = [0.0; 3];
                e[j] = 1.0;
                let (mut y, mut back) = ([0.0; 6], [0.0; 3]);
                modes.to_modes(&e, &mut y);
                modes.to_joints(&y, &mut back);
                y.iter_mut()
                    .enumerate()
                    .for_each(|(k, y)| *y *= modes.rate(k));
                let mut got = [0.0; 3];
                modes.to_joints(&y, &mut got);
                for i in 0..3 {
                    assert!(
                        (back[i] - e[i]).abs() < 1e-12,
                        "h {h}, column {j}: {back:?}"
                    );
                    assert!(
                        (got[i] - want[i]).abs() < 1e-9 * (1.0 + want[i].abs()),
                        "h {h}, column {j}: {got:?} vs {want:?}"
                    );
                }
            }
        }
    }

    /// A damping blown up to infinity gives no modes (the step then
    /// reports the state non-finite) instead of an eigenproblem that
    /// never converges.
    #[test]
    fn no_modes_from_a_non_finite_damping() {
        let mut chol = Cholesky::new(3);
        chol.matrix_mut().copy_from_slice(&M);
        chol.factor().unwrap_or_else(|row| panic!("row {row}"));
        let d = [0.0, f64::INFINITY, 5e3];
        let mut shares = [0.0; 3];
        damping_shares(&chol, &d, &mut [0.0; 3], &mut shares);
        let mut modes = Modes::new(chol.clone(), 3);
        assert!(!modes.update(&chol, &d, &shares, 1e-3));
    }

    /// Two arms on a fixed base do not couple: G splits into one block per
    /// arm, and the modes from the blocks still give M⁻¹ D_S whole.
    #[test]
    fn uncoupled_groups_take_one_eigenproblem_each() {
        let n = 4;
        // Joints 0, 1 one arm, 2, 3 the other.
        let same = |i: usize, j: usize| (i < 2) == (j < 2);
        let mut m = [0.0; 16];
        for i in 0..n {
            for j in 0..n {
                if same(i, j) {
                    m[i * n + j] = if i == j { 0.3 + i as f64 } else { 0.1 };
                }
            }
        }
        let d = [5e3, 0.0, 2e3, 1.0];
        let mut chol = Cholesky::with_structure(vec![1, 0, 3, 2], same);
        assert_ne!(chol.group(0), chol.group(2));
        chol.matrix_mut().copy_from_slice(&m);
        chol.factor().unwrap_or_else(|row| panic!("row {row}"));
        let mut shares = [0.0; 4];
        // Each arm's damping mild on its own (h·trace 0.41 and 0.39), the
        // two together not: the fastest rate is one arm's, so the step is
        // mild.
        let top = damping_shares(&chol, &[120.0, 0.0, 900.0, 0.0], &mut [0.0; 4], &mut shares);
        assert!(1e-3 * top < MILD_DAMPING && 1e-3 * shares.iter().sum::<f64>() > MILD_DAMPING);
        damping_shares(&chol, &d, &mut [0.0; 4], &mut shares);
        let mut modes = Modes::new(chol.clone(), n);
        assert!(modes.update(&chol, &d, &shares, 1e-3));
        assert_eq!(modes.stiff, [0, 2]);
        assert_eq!(modes.len(), n + 2);
        for j in 0..n {
            let mut want = [0.0; 4];
            want[j] = if modes.stiff.contains(&j) { d[j] } else { 0.0 };
            chol.solve(&mut want);
            let mut e = [0.0; 4];
            e[j] = 1.0;
            let (mut y, mut back, mut got) = ([0.0; 8], [0.0; 4], [0.0; 4]);
            modes.to_modes(&e, &mut y);
            modes.to_joints(&y, &mut back);
            y.iter_mut()
                .enumerate()
                .for_each(|(k, y)| *y *= modes.rate(k));
            modes.to_joints(&y, &mut got);
            for i in 0..n {
                assert!((back[i] - e[i]).abs() < 1e-12, "column {j}: {back:?}");
                assert!(
                    (got[i] - want[i]).abs() < 1e-9 * (1.0 + want[i].abs()),
                    "column {j}: {got:?} vs {want:?}"
                );
            }
        }
    }

    /// φ1(A) M⁻¹ from the split equals W diag(φ1) Wᵀ from the whole
    /// eigendecomposition of L⁻¹ D_S L⁻ᵀ (W = L⁻ᵀ V), made here with
    /// nalgebra on dense matrices: with one joint stiff and with all.
    #[test]
    fn the_response_equals_the_whole_eigendecomposition() {
        use nalgebra::Matrix3;
        let m = Matrix3::from_row_slice(&M);
        let l = m.cholesky().map(|c| c.l()).unwrap_or_else(|| panic!("M"));
        let l_inv = l.try_inverse().unwrap_or_else(|| panic!("L"));
        for (h, stiff) in [(1e-3, [0.0, 0.0, D[2]]), (1.0, D)] {
            let s = l_inv * Matrix3::from_diagonal(&stiff.into()) * l_inv.transpose();
            let eig = SymmetricEigen::new(s);
            let w = l_inv.transpose() * eig.eigenvectors;
            let phi = Matrix3::from_fn(|i, j| {
                if i == j {
                    Weights::new(eig.eigenvalues[i].max(0.0), h).phi1
                } else {
                    0.0
                }
            });
            let want = w * phi * w.transpose();
            let (_, modes) = modes_at(h);
            let mut got = [0.0; 9];
            modes.response_columns(|w| w.phi1, &[0, 1, 2], &mut got);
            for i in 0..3 {
                for j in 0..3 {
                    let (g, x) = (got[j * 3 + i], want[(i, j)]);
                    assert!(
                        (g - x).abs() < 1e-10 * (1.0 + x.abs()),
                        "h {h} ({i},{j}): {g} vs {x}"
                    );
                }
            }
        }
    }

    /// The response matrix's columns are the responses to unit impulses.
    #[test]
    fn response_matrix_columns_are_unit_responses() {
        for h in [1e-3, 1.0] {
            let (_, modes) = modes_at(h);
            let mut all = [0.0; 9];
            modes.response_columns(|w| w.phi1, &[0, 1, 2], &mut all);
            for j in 0..3 {
                let mut e = [0.0; 3];
                e[j] = 1.0;
                let mut col = [0.0; 3];
                modes.response(|w| w.phi1, &e, &mut col);
                for i in 0..3 {
                    assert!((all[i * 3 + j] - col[i]).abs() < 1e-12 * (1.0 + col[i].abs()));
                }
            }
        }
    }

    /// tr(M⁻¹D) from the shares equals the trace of M⁻¹D computed whole.
    #[test]
    fn damping_shares_sum_to_the_trace_of_m_inverse_d() {
        let (chol, _) = modes_at(1e-3);
        let mut want = 0.0;
        for j in 0..3 {
            let mut col = [0.0; 3];
            col[j] = D[j];
            chol.solve(&mut col);
            want += col[j];
        }
        let mut shares = [0.0; 3];
        let got = damping_shares(&chol, &D, &mut [0.0; 3], &mut shares);
        assert!((got - want).abs() < 1e-12 * want, "{got} vs {want}");
        assert_eq!(shares[0], 0.0);
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
