//! Active-set polishing of one joint's MPC solution, as OSQP's `polish`
//! does: clarabel's interior-point solution at its default duality gap
//! (1e-8) leaves u₀ up to 6e-4 off where a row is active; given the rows
//! it finds active, one small equality-constrained QP over the inputs
//! gives the exact optimum. Polishing is accepted only when its answer is
//! feasible on every row and its multipliers are nonnegative (then it is
//! the QP's optimum by the KKT conditions); otherwise the solver's own
//! solution stands.
//!
//! The QP is condensed once, from the same P, A and layout the solver was
//! built with: the dynamics rows give the states as x_s = S(b_eq − A_w w)
//! with S = A_s⁻¹, so x = T w + Z b_eq over the inputs w.

use clarabel::algebra::CscMatrix;
use nalgebra::{DMatrix, DVector};

/// How far a polished solution may break a row, or a multiplier be
/// negative, relative to the row's (or the multipliers') scale.
const SLACK: f64 = 1e-9;

/// How many active-set changes the polish may make before it gives up
/// (the solver's own solution then stands).
const MOVES: usize = 6;

/// One joint's QP condensed onto its inputs.
#[derive(Debug)]
pub(crate) struct Polish {
    /// Cost over w: ½ wᵀ H w + (F b_eq)ᵀ w.
    h: DMatrix<f64>,
    f: DMatrix<f64>,
    /// Inequality rows over w: C w ≤ b_in − D b_eq.
    c: DMatrix<f64>,
    d: DMatrix<f64>,
    /// How many equality rows (and state variables) come first.
    eq: usize,
}

impl Polish {
    /// Condenses the QP (P upper triangle, A with the `eq` equality rows
    /// first, the states the first `eq` variables). None if the dynamics
    /// block is singular (it never is: it is unit lower triangular).
    pub(crate) fn new(p: &CscMatrix<f64>, a: &CscMatrix<f64>, eq: usize) -> Option<Self> {
        let (p, a) = (dense(p), dense(a));
        let p = &p + p.transpose() - DMatrix::from_diagonal(&p.diagonal());
        let n = p.ncols();
        let inputs = n - eq;
        let s = a.view((0, 0), (eq, eq)).into_owned().try_inverse()?;
        let a_w = a.view((0, eq), (eq, inputs));
        let mut t = DMatrix::zeros(n, inputs);
        t.view_mut((0, 0), (eq, inputs)).copy_from(&(-&s * a_w));
        t.view_mut((eq, 0), (inputs, inputs)).fill_with_identity();
        let mut z = DMatrix::zeros(n, eq);
        z.view_mut((0, 0), (eq, eq)).copy_from(&s);
        let a_in = a.view((eq, 0), (a.nrows() - eq, n));
        Some(Self {
            h: t.transpose() * &p * &t,
            f: t.transpose() * &p * &z,
            c: a_in * &t,
            d: a_in * &z,
            eq,
        })
    }

    /// The exact inputs w for the constraint vector `b`, given the solver's
    /// slacks `s` and multipliers `z` (all rows, equalities first), or
    /// None if no checked optimum is found. The rows the solver finds
    /// active (z > s) start the search; a row with a negative multiplier
    /// is dropped and a broken row added, one at a time, as an active-set
    /// method does: at a degenerate optimum the solver can call a row
    /// active that carries no force.
    pub(crate) fn inputs(&self, b: &[f64], s: &[f64], z: &[f64]) -> Option<DVector<f64>> {
        let b_eq = DVector::from_column_slice(&b[..self.eq]);
        let rhs = DVector::from_column_slice(&b[self.eq..]) - &self.d * &b_eq;
        let f = &self.f * &b_eq;
        let mut active: Vec<usize> = (0..self.c.nrows())
            .filter(|&i| z[self.eq + i] > s[self.eq + i])
            .collect();
        for _ in 0..MOVES {
            // Rows come in pairs (upper 2r, lower 2r + 1). A pair both
            // active is one equality (a bound tightened to zero): its upper
            // row stands for it, with a multiplier of either sign.
            let pair = |i: usize| active.contains(&(i ^ 1));
            let held: Vec<usize> = active
                .iter()
                .copied()
                .filter(|&i| i % 2 == 0 || !pair(i))
                .collect();
            let (w, multipliers) = self.equality_qp(&f, &rhs, &held)?;
            let scale = multipliers.amax().max(1.0);
            let negative = held
                .iter()
                .zip(multipliers.iter())
                .map(|(&i, &l)| match pair(i) {
                    true => f64::NEG_INFINITY,
                    false => -l - SLACK * scale,
                });
            if let Some(weakest) = most(negative) {
                let row = held[weakest];
                active.retain(|&i| i != row);
                continue;
            }
            let excess = &self.c * &w - &rhs;
            let broken = (0..excess.len()).map(|i| excess[i] - SLACK * rhs[i].abs().max(1.0));
            if let Some(worst) = most(broken) {
                active.push(worst);
                continue;
            }
            return Some(w);
        }
        None
    }

    /// min ½ wᵀHw + fᵀw subject to the `active` rows held as equalities:
    /// w and the rows' multipliers, or None if the KKT system is singular
    /// or its solution not finite.
    fn equality_qp(
        &self,
        f: &DVector<f64>,
        rhs: &DVector<f64>,
        active: &[usize],
    ) -> Option<(DVector<f64>, DVector<f64>)> {
        let (n, m) = (self.h.nrows(), active.len());
        let mut kkt = DMatrix::zeros(n + m, n + m);
        kkt.view_mut((0, 0), (n, n)).copy_from(&self.h);
        let mut right = DVector::zeros(n + m);
        right.rows_mut(0, n).copy_from(&-f);
        for (k, &i) in active.iter().enumerate() {
            kkt.view_mut((n + k, 0), (1, n)).copy_from(&self.c.row(i));
            kkt.view_mut((0, n + k), (n, 1))
                .copy_from(&self.c.row(i).transpose());
            right[n + k] = rhs[i];
        }
        let solution = kkt.lu().solve(&right)?;
        solution.iter().all(|x| x.is_finite()).then(|| {
            (
                solution.rows(0, n).into_owned(),
                solution.rows(n, m).into_owned(),
            )
        })
    }
}

/// The index of the largest positive value, if any is positive.
fn most(values: impl Iterator<Item = f64>) -> Option<usize> {
    values
        .enumerate()
        .filter(|(_, v)| *v > 0.0)
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// A sparse matrix as a dense one.
fn dense(m: &CscMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(m.m, m.n);
    for col in 0..m.n {
        for k in m.colptr[col]..m.colptr[col + 1] {
            out[(m.rowval[k], col)] += m.nzval[k];
        }
    }
    out
}
