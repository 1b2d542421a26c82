"""The paper's law in numpy, written from SPEC.md (§3–§10), not from the Rust code.

The RL neuroadaptive controller under deferred constraints: a shifting
function γ(t) switches a per-joint (or norm) barrier on by T_c, the virtual
control α and the torque τ = Ŵ_aᵀS_a − K2 Z2 − γ Z1γ/(β D), and an
actor-critic pair of Gaussian RBF networks whose weights are advanced
exactly over each period (SPEC §9).

    testbed run --mode lockstep --controller-cmd "python3 python/examples/nac.py"

Every parameter comes from the scenario's [controller] table.
"""

from __future__ import annotations

import numpy as np

import testbed_controller as tc


def shifting(t: float, tc_: float) -> tuple[float, float]:
    """γ(t), γ̇(t) of SPEC §3 (t before 0 counts as 0)."""
    t = max(t, 0.0)
    if t >= tc_:
        return 1.0, 0.0
    rest = tc_ - t
    x = rest / tc_
    return 1.0 - x * x * x, 3.0 * rest * rest / (tc_ * tc_ * tc_)


class Rbf:
    """Gaussian RBFs S_j(x) = exp(−‖x − μ_j‖²/η²) (SPEC §8): `diagonal`
    centres μ_j = c_j·1, or `per-input`, N one-dimensional neurons per input."""

    def __init__(self, layout: str, neurons: int, c_min: float, c_max: float, width: float):
        if neurons == 1:
            self.c = np.array([0.5 * (c_min + c_max)])
        else:
            step = (c_max - c_min) / (neurons - 1)
            self.c = c_min + step * np.arange(neurons)
        self.layout = layout
        self.inv_w2 = 1.0 / (width * width)

    def features(self, x: np.ndarray) -> np.ndarray:
        if self.layout == "diagonal":
            d = x[None, :] - self.c[:, None]
            return np.exp(-(d * d).sum(axis=1) * self.inv_w2)
        d = x[:, None] - self.c[None, :]
        return np.exp(-d * d * self.inv_w2).ravel()

    def directional_derivative(self, x: np.ndarray, v: np.ndarray, s: np.ndarray) -> np.ndarray:
        """∇S·v: component j is −2 S_j (x − μ_j)ᵀ v / η²."""
        if self.layout == "diagonal":
            proj = ((x[None, :] - self.c[:, None]) * v[None, :]).sum(axis=1)
            return -2.0 * s * proj * self.inv_w2
        d = (x[:, None] - self.c[None, :]) * v[:, None]
        return -2.0 * s * d.ravel() * self.inv_w2


def advance_exact(w: np.ndarray, s: np.ndarray, c, sigma: float, eta: float, dt: float) -> np.ndarray:
    """The exact solution over dt of ẇ = −σ(s sᵀ + ηI)w − σ c s with s, c held
    (SPEC §9). `w` is N or N×m (one column per c)."""
    decay = np.exp(-sigma * eta * dt)
    s2 = float(s @ s)
    if s2 == 0.0:
        return decay * w
    norm = np.sqrt(s2)
    u = s / norm
    p = u @ w
    p_inf = -np.asarray(c) * norm / (s2 + eta)
    p_new = p_inf + (p - p_inf) * np.exp(-sigma * (s2 + eta) * dt)
    return decay * w + np.multiply.outer(u, p_new - decay * p)


def advance_euler(w: np.ndarray, s: np.ndarray, c, sigma: float, eta: float, dt: float) -> np.ndarray:
    """Explicit Euler (SPEC §9 keeps it to show the instability)."""
    g = s @ w + np.asarray(c)
    return w + dt * (-sigma * np.multiply.outer(s, g) - sigma * eta * w)


class PaperLaw(tc.Controller):
    """The paper's law (`nac`)."""

    def setup(self, run: tc.RunInfo) -> None:
        p = run.params
        if p.get("law", "nac") != "nac":
            raise ValueError(f"this example computes the paper's law, not '{p['law']}'")
        n = run.dof
        self.p = p
        self.n = n
        self.dt = run.dt
        self.k1 = run.gain("k1")
        self.k2 = run.gain("k2")
        rbf = lambda: Rbf(p["rbf_layout"], p["neurons"], p["center_min"], p["center_max"], p["width"])  # noqa: E731
        self.actor, self.critic = rbf(), rbf()
        per = 1 if p["rbf_layout"] == "diagonal" else None
        na = p["neurons"] * (per or 4 * n)
        nc = p["neurons"] * (per or 2 * n)
        self.wa = np.zeros((na, n))
        self.wc = np.zeros(nc)
        self.advance = advance_exact if p["integrator"] == "exact" else advance_euler
        self.prev_zc = None
        self.prev_t = None
        self.diag: dict = {}

    def _barrier(self, z1, z1g, ref):
        """The bound, its rate and ‖Z1‖² each joint sees (SPEC §5)."""
        if self.p["barrier"] == "per-joint":
            return ref.kc, ref.kc_dot, z1 * z1, z1g * z1g
        m = int(np.argmin(ref.kc))
        full = lambda v: np.full(self.n, v)  # noqa: E731
        return full(ref.kc[m]), full(ref.kc_dot[m]), full(z1 @ z1), full(z1g @ z1g)

    def step(self, state: tc.State, ref: tc.Reference) -> np.ndarray:
        p, t = self.p, state.t
        beta = p["beta"]
        gamma, gdot = shifting(t, p["tc"])
        z1 = state.q - ref.q_d
        z1g = gamma * z1
        kc, kc_dot, z1_sq, z1g_sq = self._barrier(z1, z1g, ref)
        d_raw = kc * kc - z1g_sq
        d_min = p["breach_epsilon"] * kc * kc
        breached = bool((d_raw < d_min).any())
        d = np.where(d_raw < d_min, d_min, d_raw)
        alpha = -self.k1 * z1 - p["a"] * gdot * gdot * z1 * z1_sq / (beta * d) + ref.qd_d + (kc_dot / kc) * z1
        z2 = state.qd - alpha
        tau_barrier = -gamma * z1g / (beta * d)

        za = np.concatenate([state.q, state.qd, z1, z2])
        zc = np.concatenate([z1, z2])
        sa = self.actor.features(za)
        sc = self.critic.features(zc)
        tau_actor = self.wa.T @ sa
        tau_feedback = -self.k2 * z2
        tau = tau_actor + tau_feedback + tau_barrier
        j_hat = float(self.wc @ sc)

        r = p["q_weight"] * float(zc @ zc) + p["r_weight"] * float(tau @ tau)
        if self.prev_t is not None and t > self.prev_t:
            zc_dot = (zc - self.prev_zc) / (t - self.prev_t)
        else:
            zc_dot = np.zeros_like(zc)
        lam = -sc / p["psi"] + self.critic.directional_derivative(zc, zc_dot, sc)
        delta = r + float(self.wc @ lam)

        self.diag = {
            "gamma": gamma, "gamma_dot": gdot, "j_hat": j_hat, "delta": delta, "r": r,
            "wc_norm": float(np.sqrt(self.wc @ self.wc)), "z1": z1, "z1g": z1g, "z2": z2,
            "alpha": alpha, "kc": kc, "d": d_raw, "tau_actor": tau_actor,
            "tau_feedback": tau_feedback, "tau_barrier": tau_barrier,
            "wa_norm": np.sqrt((self.wa * self.wa).sum(axis=0)),
            "barrier_breached": int(breached),
        }
        if not (np.isfinite(tau).all() and np.isfinite(lam).all() and np.isfinite([r, delta]).all()):
            return np.full(self.n, np.nan)  # a fault: zero torque, no update (SPEC §10)

        dt = self.dt
        self.prev_zc, self.prev_t = zc, t
        self.wc = self.advance(self.wc, lam, r, p["sigma_c"], p["eta_c"], dt)
        c = z2 / p["sigma_a"] + p["k_a"] * j_hat
        self.wa = self.advance(self.wa, sa, c, p["sigma_a"], p["eta_a"], dt)
        return tau

    def diagnostics(self) -> dict:
        return self.diag


if __name__ == "__main__":
    tc.run(PaperLaw())
