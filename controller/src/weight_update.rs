//! Advancing the actor and critic weights over one control period (SPEC §9).
//!
//! Both laws have the form ẇ = -σ (s sᵀ + η I) w - σ c s with s and c held
//! over the step. The matrix is rank-one plus diagonal, so the ODE splits
//! into the part of w along s, which relaxes to p∞ at rate σ(‖s‖² + η), and
//! the part across s, which decays at rate ση. Solving both exactly is
//! stable for any Δt; explicit Euler is not once Δt σ (‖s‖² + η) > 2.

/// w ← the exact solution of ẇ = -σ (s sᵀ + η I) w - σ c s after `dt`.
pub fn advance_exact(w: &mut [f64], s: &[f64], c: f64, sigma: f64, eta: f64, dt: f64) {
    let decay = (-sigma * eta * dt).exp();
    let s2: f64 = s.iter().map(|x| x * x).sum();
    if s2 == 0.0 {
        w.iter_mut().for_each(|wi| *wi *= decay);
        return;
    }
    let norm = s2.sqrt();
    let p = dot(s, w) / norm;
    let p_inf = -c * norm / (s2 + eta);
    let p_new = p_inf + (p - p_inf) * (-sigma * (s2 + eta) * dt).exp();
    // w⊥ decays, the component along u = s/‖s‖ becomes p_new:
    // w ← decay (w - p u) + p_new u = decay w + (p_new - decay p) u.
    let k = (p_new - decay * p) / norm;
    for (wi, si) in w.iter_mut().zip(s) {
        *wi = decay * *wi + k * si;
    }
}

/// w ← w + dt ẇ (explicit Euler), for `integrator = "euler"`.
pub fn advance_euler(w: &mut [f64], s: &[f64], c: f64, sigma: f64, eta: f64, dt: f64) {
    let g = dot(s, w) + c;
    for (wi, si) in w.iter_mut().zip(s) {
        *wi += dt * (-sigma * g * si - sigma * eta * *wi);
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The same ODE integrated with classic RK4 at a step far below its
    /// fastest time constant.
    fn rk4(w: &[f64], s: &[f64], c: f64, sigma: f64, eta: f64, dt: f64, sub: usize) -> Vec<f64> {
        let f = |w: &[f64]| -> Vec<f64> {
            let g = dot(s, w) + c;
            w.iter()
                .zip(s)
                .map(|(wi, si)| -sigma * g * si - sigma * eta * wi)
                .collect()
        };
        let h = dt / sub as f64;
        let mut w = w.to_vec();
        for _ in 0..sub {
            let k1 = f(&w);
            let w2: Vec<f64> = w.iter().zip(&k1).map(|(a, k)| a + 0.5 * h * k).collect();
            let k2 = f(&w2);
            let w3: Vec<f64> = w.iter().zip(&k2).map(|(a, k)| a + 0.5 * h * k).collect();
            let k3 = f(&w3);
            let w4: Vec<f64> = w.iter().zip(&k3).map(|(a, k)| a + h * k).collect();
            let k4 = f(&w4);
            for i in 0..w.len() {
                w[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        w
    }

    proptest! {
        /// Exact update = finely sub-stepped RK4 of the same ODE. With the
        /// fastest rate λ = σ(‖s‖² + η) ≤ 50·(37.5 + 0.5) and 2 000 RK4 steps
        /// over 1 ms, λh ≤ 1e-3 and RK4's local error (λh)⁵/120 ≈ 1e-17 is
        /// negligible: the bound is set by round-off over 2 000 steps.
        #[test]
        fn exact_matches_fine_rk4(
            w in proptest::collection::vec(-3.0..3.0f64, 6),
            s in proptest::collection::vec(-2.5..2.5f64, 6),
            c in -50.0..50.0f64,
            eta in 0.01..0.5f64,
        ) {
            let (sigma, dt) = (50.0, 1e-3);
            let mut exact = w.clone();
            advance_exact(&mut exact, &s, c, sigma, eta, dt);
            let fine = rk4(&w, &s, c, sigma, eta, dt, 2_000);
            for (a, b) in exact.iter().zip(&fine) {
                prop_assert!((a - b).abs() < 1e-9 * (1.0 + b.abs()), "{a} vs {b}");
            }
        }

        /// Stable for any Δt: the weights approach the fixed point, never grow past it.
        #[test]
        fn exact_is_stable_for_any_dt(dt in 1e-4..10.0f64, c in -10.0..10.0f64) {
            let s = [20.0, -15.0, 3.0];
            let mut w = [1.0, 2.0, -1.0];
            advance_exact(&mut w, &s, c, 50.0, 0.5, dt);
            // Fixed point: w* = -c s / (‖s‖² + η).
            let s2: f64 = s.iter().map(|x| x * x).sum();
            let bound = 2.5f64.max(c.abs() * s2.sqrt() / (s2 + 0.5)) + 1e-12;
            prop_assert!(w.iter().map(|x| x * x).sum::<f64>().sqrt() <= bound);
        }
    }

    #[test]
    fn zero_feature_vector_only_decays() {
        let mut w = [1.0, -2.0];
        advance_exact(&mut w, &[0.0, 0.0], 5.0, 50.0, 0.5, 0.01);
        let d = (-50.0f64 * 0.5 * 0.01).exp();
        assert_eq!(w, [d, -2.0 * d]);
    }

    #[test]
    fn euler_by_hand() {
        // w = [1, 2], s = [0.5, -1], c = 3, σ = 10, η = 0.1, dt = 0.01:
        // sᵀw + c = 0.5 - 2 + 3 = 1.5;
        // ẇ = -10·1.5·s - 10·0.1·w = [-7.5 - 1, 15 - 2] = [-8.5, 13].
        let mut w = [1.0, 2.0];
        advance_euler(&mut w, &[0.5, -1.0], 3.0, 10.0, 0.1, 0.01);
        assert!((w[0] - (1.0 - 0.085)).abs() < 1e-15);
        assert!((w[1] - (2.0 + 0.13)).abs() < 1e-15);
    }

    #[test]
    fn euler_diverges_where_exact_does_not() {
        // Δt σ (‖s‖² + η) = 1e-3·50·(100 + 0.5) ≈ 5 > 2: Euler's factor is about -4 per step.
        let s = [10.0];
        let (mut e, mut x) = ([1.0], [1.0]);
        for _ in 0..20 {
            advance_euler(&mut e, &s, 0.0, 50.0, 0.5, 1e-3);
            advance_exact(&mut x, &s, 0.0, 50.0, 0.5, 1e-3);
        }
        assert!(e[0].abs() > 1e10);
        assert!(x[0].abs() < 1e-10);
    }
}
