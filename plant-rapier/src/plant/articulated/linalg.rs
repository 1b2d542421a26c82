//! A Cholesky factorisation of a small symmetric positive-definite matrix in
//! place, with no allocation per call (the joint-space inertia, factored
//! four times per RK4 step).

/// An n × n matrix (row-major) and, after `factor`, its lower factor L.
#[derive(Debug, Clone)]
pub(super) struct Cholesky {
    n: usize,
    a: Vec<f64>,
}

impl Cholesky {
    pub(super) fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
        }
    }

    /// The matrix to fill before `factor` (row-major).
    pub(super) fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.a
    }

    /// A = L Lᵀ in place; Err(row) where A is not positive definite (or NaN).
    pub(super) fn factor(&mut self) -> Result<(), usize> {
        let (n, a) = (self.n, &mut self.a);
        for j in 0..n {
            let mut d = a[j * n + j];
            for k in 0..j {
                d -= a[j * n + k] * a[j * n + k];
            }
            // Not positive, or NaN.
            if d.is_nan() || d <= 0.0 {
                return Err(j);
            }
            let d = d.sqrt();
            a[j * n + j] = d;
            for i in j + 1..n {
                let mut s = a[i * n + j];
                for k in 0..j {
                    s -= a[i * n + k] * a[j * n + k];
                }
                a[i * n + j] = s / d;
            }
        }
        Ok(())
    }

    /// x = A⁻¹ b in place, after `factor`.
    pub(super) fn solve(&self, b: &mut [f64]) {
        self.forward(b);
        self.backward(b);
    }

    /// x = L⁻¹ b in place, after `factor`.
    pub(super) fn forward(&self, b: &mut [f64]) {
        let (n, l) = (self.n, &self.a);
        for i in 0..n {
            let mut s = b[i];
            for k in 0..i {
                s -= l[i * n + k] * b[k];
            }
            b[i] = s / l[i * n + i];
        }
    }

    /// x = L⁻ᵀ b in place, after `factor`.
    pub(super) fn backward(&self, b: &mut [f64]) {
        let (n, l) = (self.n, &self.a);
        for i in (0..n).rev() {
            let mut s = b[i];
            for k in i + 1..n {
                s -= l[k * n + i] * b[k];
            }
            b[i] = s / l[i * n + i];
        }
    }

    /// A⁻¹ into `out` (row-major; symmetric, so column j is row j), after
    /// `factor`. L⁻¹ e_j is zero above row j, so its forward solve starts
    /// there: two thirds of the work of n whole solves saved.
    pub(super) fn inverse_into(&self, out: &mut [f64]) {
        let (n, l) = (self.n, &self.a);
        for j in 0..n {
            let x = &mut out[j * n..(j + 1) * n];
            x[..j].iter_mut().for_each(|v| *v = 0.0);
            for i in j..n {
                let start = if i == j { 1.0 } else { 0.0 };
                let s = (j..i).fold(start, |s, k| s - l[i * n + k] * x[k]);
                x[i] = s / l[i * n + i];
            }
            self.backward(x);
        }
    }

    /// L_ij (i ≥ j), after `factor`.
    pub(super) fn lower(&self, i: usize, j: usize) -> f64 {
        self.a[i * self.n + j]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_spd_system_and_refuses_a_singular_one() {
        let mut c = Cholesky::new(3);
        let a = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        c.matrix_mut().copy_from_slice(&a);
        c.factor().unwrap_or_else(|row| panic!("row {row}"));
        let mut inv = [0.0; 9];
        c.inverse_into(&mut inv);
        for j in 0..3 {
            let mut col = [0.0; 3];
            col[j] = 1.0;
            c.solve(&mut col);
            for i in 0..3 {
                assert!((inv[j * 3 + i] - col[i]).abs() < 1e-15, "{inv:?}");
            }
        }
        let mut x = [1.0, -2.0, 0.5];
        c.solve(&mut x);
        for i in 0..3 {
            let ax: f64 = (0..3).map(|k| a[i * 3 + k] * x[k]).sum();
            assert!((ax - [1.0, -2.0, 0.5][i]).abs() < 1e-14);
        }
        c.matrix_mut()
            .copy_from_slice(&[1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(c.factor(), Err(1));
        c.matrix_mut()[0] = f64::NAN;
        assert_eq!(c.factor(), Err(0));
    }
}
