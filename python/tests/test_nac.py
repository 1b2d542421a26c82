"""The numpy paper law's pieces against SPEC.md, by hand and by integration."""

import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "examples"))
import nac  # noqa: E402


def rk4(w, s, c, sigma, eta, dt, sub=2000):
    f = lambda w: -sigma * np.multiply.outer(s, s @ w + c) - sigma * eta * w  # noqa: E731
    h = dt / sub
    for _ in range(sub):
        k1 = f(w)
        k2 = f(w + 0.5 * h * k1)
        k3 = f(w + 0.5 * h * k2)
        k4 = f(w + h * k3)
        w = w + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return w


class PaperLawPieces(unittest.TestCase):
    def test_shifting_function_end_points(self):
        self.assertEqual(nac.shifting(0.0, 2.0), (0.0, 1.5))
        self.assertEqual(nac.shifting(1.0, 2.0), (0.875, 0.375))
        self.assertEqual(nac.shifting(2.0, 2.0), (1.0, 0.0))
        self.assertEqual(nac.shifting(-1.0, 2.0), (0.0, 1.5))

    def test_exact_update_matches_fine_rk4_for_one_and_many_columns(self):
        rng = np.random.default_rng(7)
        for _ in range(20):
            s = rng.uniform(-2.5, 2.5, 6)
            w = rng.uniform(-3, 3, (6, 3))
            c = rng.uniform(-50, 50, 3)
            exact = nac.advance_exact(w, s, c, 50.0, 0.3, 1e-3)
            fine = rk4(w, s, c, 50.0, 0.3, 1e-3)
            np.testing.assert_allclose(exact, fine, rtol=1e-9, atol=1e-9)
            one = nac.advance_exact(w[:, 0], s, c[0], 50.0, 0.3, 1e-3)
            np.testing.assert_allclose(one, exact[:, 0], rtol=0, atol=1e-15)

    def test_exact_update_with_no_features_only_decays(self):
        w = np.array([1.0, -2.0])
        out = nac.advance_exact(w, np.zeros(2), 5.0, 50.0, 0.5, 0.01)
        np.testing.assert_allclose(out, w * np.exp(-50 * 0.5 * 0.01), rtol=1e-15)

    def test_rbf_derivative_matches_finite_difference(self):
        for layout in ("diagonal", "per-input"):
            rbf = nac.Rbf(layout, 10, -5.0, 5.0, 1.0)
            x = np.array([0.3, -0.2, 0.8, 0.1])
            v = np.array([1.0, -2.0, 0.5, 3.0])
            s = rbf.features(x)
            h = 1e-6
            fd = (rbf.features(x + h * v) - rbf.features(x - h * v)) / (2 * h)
            np.testing.assert_allclose(rbf.directional_derivative(x, v, s), fd, atol=1e-8)

    def test_diagonal_centres_span_the_range_with_ends(self):
        rbf = nac.Rbf("diagonal", 10, -5.0, 5.0, 1.0)
        self.assertEqual(rbf.c[0], -5.0)
        self.assertAlmostEqual(rbf.c[-1], 5.0, places=14)
        s = rbf.features(np.zeros(4))
        self.assertAlmostEqual(s[0], np.exp(-4 * 25.0))


if __name__ == "__main__":
    unittest.main()
