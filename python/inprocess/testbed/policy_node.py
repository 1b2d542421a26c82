"""A trained `LinearPolicy` as the testbed's controller node:

    testbed run --controller-cmd "python -m testbed.policy_node --policy POLICY.npz"
    testbed compare --controller-cmd policy="python -m testbed.policy_node --policy POLICY.npz"

Each decision (every `decimation` steps, as the environment's) builds the
environment's observation from the measured state and the reference
sample, exactly as `ArmTrackingEnv` does (scaled or not), and every step
applies the torque the environment would (the held residual on the same
built-in law, from the policy's scenario): a lockstep run of the scenario
with the episode's seed reproduces the environment's episode.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

import testbed_controller as tc

from ._native import LAWS, Law
from .policy import LinearPolicy


class PolicyController(tc.Controller):
    name = "policy"

    def __init__(self, policy: LinearPolicy):
        policy.check()
        self.policy = policy
        env = policy.env
        self.n = int(env["dof"])
        self.scale = np.asarray(env["torque_scale"], dtype=np.float64)
        self.steps = int(env["steps"])
        self.base_law = env.get("base_law")
        if self.base_law is not None and self.base_law not in LAWS:
            raise ValueError(f"env.base_law = {self.base_law!r} is not a law ({', '.join(LAWS)})")
        self.span = float(env.get("residual_scale", 0.2)) if self.base_law else 1.0
        self.decimation = int(env.get("decimation", 1))
        self.scale_obs = bool(env.get("scale_obs", False))
        self.velocity = np.asarray(env.get("velocity_scale", np.ones(self.n)), dtype=np.float64)
        self.law = None
        self.obs = np.empty(7 * self.n + 1)
        self.residual = np.zeros(self.n)

    def setup(self, run: tc.RunInfo) -> None:
        if run.dof != self.n:
            raise ValueError(f"the policy is for {self.n} joints; this run's arm has {run.dof}")
        if self.base_law:
            env = self.policy.env
            self.law = Law(self.base_law, scenario=env.get("scenario"), robot=env.get("robot"),
                           set=env.get("set"))

    def step(self, state: tc.State, ref: tc.Reference) -> np.ndarray:
        if state.seq % self.decimation == 0:
            n, o = self.n, self.obs
            o[0:n] = state.q - ref.q_d
            o[n:2 * n] = state.qd - ref.qd_d
            o[2 * n:3 * n] = state.q
            o[3 * n:4 * n] = state.qd
            o[4 * n:5 * n] = ref.q_d
            o[5 * n:6 * n] = ref.qd_d
            o[6 * n:7 * n] = ref.kc
            o[7 * n] = state.seq / self.steps
            if self.scale_obs:
                # The same divisions as the environment's, in the same order.
                o[0:n] = o[0:n] / ref.kc
                for k in (1, 3, 5):
                    o[k * n:(k + 1) * n] = o[k * n:(k + 1) * n] / self.velocity
            a = self.policy.act(o)
            self.residual = a * self.span * self.scale
        if self.law is None:
            return self.residual
        base = self.law.step(state.t, state.q, state.qd, ref.q_d, ref.qd_d, ref.qdd_d, ref.kc,
                             ref.kc_dot)
        return base + self.residual


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description="A trained testbed policy as the controller node.")
    p.add_argument("--policy", required=True, help="the policy file (LinearPolicy.save)")
    args, rest = p.parse_known_args(sys.argv[1:] if argv is None else argv)
    try:
        controller = PolicyController(LinearPolicy.load(args.policy))
    except (OSError, ValueError, KeyError, TypeError) as e:
        # One line naming the file, not a traceback (zipfile and json
        # errors are ValueErrors or OSErrors).
        raise SystemExit(f"testbed.policy_node: {args.policy}: {e}") from None
    tc.run(controller, rest)


if __name__ == "__main__":
    main()
