//! 3×3 products written out. nalgebra runs `Matrix3 * Matrix3` and
//! `Matrix3 * Vector3` through its general gemm/gemv loops, which the
//! compiler did not inline: a quarter of a 12-joint arm's plant step went to
//! their inner loops. These sum the same products in the same order, so the
//! results are bit for bit nalgebra's.

use nalgebra::{Matrix3, Vector3};

/// a · v.
#[inline]
pub(super) fn mv(a: &Matrix3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(
        a[(0, 0)] * v[0] + a[(0, 1)] * v[1] + a[(0, 2)] * v[2],
        a[(1, 0)] * v[0] + a[(1, 1)] * v[1] + a[(1, 2)] * v[2],
        a[(2, 0)] * v[0] + a[(2, 1)] * v[1] + a[(2, 2)] * v[2],
    )
}

/// aᵀ · v.
#[inline]
pub(super) fn tv(a: &Matrix3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(
        a[(0, 0)] * v[0] + a[(1, 0)] * v[1] + a[(2, 0)] * v[2],
        a[(0, 1)] * v[0] + a[(1, 1)] * v[1] + a[(2, 1)] * v[2],
        a[(0, 2)] * v[0] + a[(1, 2)] * v[1] + a[(2, 2)] * v[2],
    )
}

/// a · b.
#[inline]
pub(super) fn mm(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| a[(i, 0)] * b[(0, j)] + a[(i, 1)] * b[(1, j)] + a[(i, 2)] * b[(2, j)])
}

/// aᵀ · b.
#[inline]
pub(super) fn tm(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| a[(0, i)] * b[(0, j)] + a[(1, i)] * b[(1, j)] + a[(2, i)] * b[(2, j)])
}

/// u · vᵀ.
#[inline]
pub(super) fn outer(u: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| u[i] * v[j])
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    /// The same bits as nalgebra's products, on awkward numbers.
    #[test]
    fn products_equal_nalgebras_bit_for_bit() {
        let a = *Rotation3::from_euler_angles(0.3, -1.1, 2.7).matrix() * 1.000_000_1;
        let b = Matrix3::new(0.3, 1e-9, -0.02, 7.1, 0.2, 0.03, -0.02, 3.3e5, 0.1);
        let v = Vector3::new(0.1 + 0.2, -1e-7, 123.456);
        assert_eq!(mv(&a, &v), a * v);
        assert_eq!(tv(&a, &v), a.transpose() * v);
        assert_eq!(mm(&a, &b), a * b);
        assert_eq!(tm(&a, &b), a.transpose() * b);
        assert_eq!(
            outer(&v, &b.column(1).into_owned()),
            v * b.column(1).transpose()
        );
    }
}
