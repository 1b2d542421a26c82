"""A PD controller in Python: the testbed's `pd` law (BASELINES.md),
τ = −K1 K2 (q − q_d) − K2 (q̇ − q̇_d), with K1 and K2 from the scenario.

    testbed run --law pd --controller-cmd "python3 python/examples/pd.py"

(`--law pd` labels the log with the law this computes, so that `testbed
replay --verify` re-drives the Rust `pd` law on the same states.)
"""

import numpy as np

import testbed_controller as tc


class PD(tc.Controller):
    def setup(self, run: tc.RunInfo) -> None:
        self.k1 = run.gain("k1")
        self.k2 = run.gain("k2")

    def step(self, state: tc.State, ref: tc.Reference) -> np.ndarray:
        e = state.q - ref.q_d
        ed = state.qd - ref.qd_d
        # The same operations in the same order as the Rust law: same bits.
        return -self.k1 * self.k2 * e - self.k2 * ed

    def diagnostics(self) -> dict:
        return {}


if __name__ == "__main__":
    tc.run(PD())
