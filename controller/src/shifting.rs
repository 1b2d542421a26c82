//! The shifting function γ(t) of eq. (2) and Lemma 1.

/// γ(t) and γ̇(t) for prescribed time `tc` (SPEC §3). Times before 0 are
/// treated as 0: a run starts at t = 0 with γ = 0.
pub fn shifting(t: f64, tc: f64) -> (f64, f64) {
    let t = t.max(0.0);
    if t >= tc {
        (1.0, 0.0)
    } else {
        let rest = tc - t;
        let x = rest / tc;
        (1.0 - x * x * x, 3.0 * rest * rest / (tc * tc * tc))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn lemma_1_a_end_points() {
        assert_eq!(shifting(0.0, 2.0), (0.0, 1.5)); // γ̇(0) = 3/T_c
        assert_eq!(shifting(2.0, 2.0), (1.0, 0.0));
        assert_eq!(shifting(7.5, 2.0), (1.0, 0.0));
        // γ(1) = 1 - (1/2)³, γ̇(1) = 3·1/8.
        assert_eq!(shifting(1.0, 2.0), (0.875, 0.375));
    }

    proptest! {
        /// Lemma 1 (b): strictly increasing on [0, T_c].
        #[test]
        fn lemma_1_b_strictly_increasing(tc in 0.1..10.0f64, a in 0.0..1.0f64, b in 0.0..1.0f64) {
            prop_assume!((a - b).abs() > 1e-6);
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            prop_assert!(shifting(lo * tc, tc).0 < shifting(hi * tc, tc).0);
        }

        /// Lemma 1 (c): γ̇ is the derivative of γ, continuous and bounded by 3/T_c.
        #[test]
        fn lemma_1_c_derivative(tc in 0.1..10.0f64, f in 0.01..0.99f64) {
            let t = f * tc;
            let h = 1e-6 * tc;
            let fd = (shifting(t + h, tc).0 - shifting(t - h, tc).0) / (2.0 * h);
            let (_, gd) = shifting(t, tc);
            prop_assert!((gd - fd).abs() < 1e-6 / tc, "γ̇ = {gd}, finite difference {fd}");
            prop_assert!(gd > 0.0 && gd <= 3.0 / tc);
        }
    }

    #[test]
    fn lemma_1_c_continuous_at_tc() {
        let tc = 2.0;
        let (g, gd) = shifting(tc - 1e-9, tc);
        assert!((1.0 - g).abs() < 1e-12);
        assert!(gd < 1e-12);
    }
}
