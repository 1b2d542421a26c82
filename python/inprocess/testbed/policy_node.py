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
import tempfile
from pathlib import Path

import numpy as np

import testbed_controller as tc

from ._native import LAWS, Law, TestbedError
from .policy import LinearPolicy, quote

#: Settings of the run's `[controller]` table a policy is refused on when
#: they differ from its training scenario's: the prescribed time and the
#: gains shape the torque it learnt a residual on and the error it saw.
#: The others the base law reads (not `law`, the run's own) are warned about.
ESSENTIAL = ("tc", "k1", "k2")


def _as_joints(value, n: int):
    """A per-joint setting (a number, or one per joint) as n floats; None
    when it is neither."""
    try:
        return np.broadcast_to(np.asarray(value, dtype=np.float64), (n,))
    except (TypeError, ValueError):
        return None


def _differs(a, b, n: int) -> bool:
    x, y = _as_joints(a, n), _as_joints(b, n)
    if x is None or y is None:
        return a != b
    return not np.array_equal(x, y)


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
        if (env.get("smoothing") or "hold") != "hold" or env.get("observe_action", False):
            # One implementation of the smoothing: the Rust node's, which
            # is the environment's own code (gym_env::ActionShaper).
            raise ValueError(f"env.smoothing = {env.get('smoothing', 'hold')!r}, env.observe_action = "
                             f"{env.get('observe_action', False)!r}: this Python node plays held actions "
                             "on the plain observation; export the policy to ONNX (testbed.onnx_export) "
                             "and run it with testbed-policy")
        self.law = None
        self.obs = np.empty(7 * self.n + 1)
        self.residual = np.zeros(self.n)

    def setup(self, run: tc.RunInfo) -> None:
        if run.dof != self.n:
            raise ValueError(f"the policy is for {self.n} joints; this run's arm has {run.dof}")
        if self.base_law:
            self.law = self._base_law()
        self._check_run(run)

    def _base_law(self) -> Law:
        """The built-in law the policy's residual is added to, from the
        policy's own scenario (a shipped one, or the one it embeds)."""
        env = self.policy.env
        robot = env.get("robot")
        with tempfile.TemporaryDirectory(prefix="testbed-policy-") as tmp:
            scenario = env.get("scenario")
            if env.get("scenario_toml") is not None:
                scenario = Path(tmp) / "policy-scenario.toml"
                scenario.write_text(env["scenario_toml"], encoding="utf-8")
            try:
                return Law(self.base_law, scenario=scenario, robot=robot, set=env.get("set"))
            except TestbedError:
                if robot is None:
                    raise
                # A file the policy names is never quoted (issue 48, N2).
                raise ValueError(f"env.robot = {quote(robot)}: the base law cannot be built on it "
                                 "(a file a policy names is not quoted; testbed.Robot(path) "
                                 "says why)") from None

    def _check_run(self, run: tc.RunInfo) -> None:
        """Refuses a run whose period or essential controller settings are
        not the policy's training scenario's (issue 48, N8: a policy trained
        with k1 = 1 ran as a row on the paper's scenario without a word);
        says on stderr which other settings differ."""
        env, notes = self.policy.env, []
        period = env.get("period_ns")
        if period is None:
            notes.append("the policy does not record its period (env.period_ns): not checked")
        elif period != run.period_ns:
            raise ValueError(f"the policy was trained at a control period of {quote(period)} ns "
                             f"(env.period_ns); this run's is {run.period_ns} ns")
        trained = env.get("controller")
        if not isinstance(trained, dict):
            trained = dict(self.law.params) if self.law is not None else None
        if trained is None:
            notes.append("the policy does not record its scenario's [controller] (env.controller): "
                         "not checked")
        else:
            for key in ESSENTIAL:
                if key in trained and key in run.params and _differs(trained[key], run.params[key], self.n):
                    raise ValueError(f"the policy was trained with controller.{key} = {quote(trained[key])}; "
                                     f"this run's controller.{key} is {quote(run.params[key])}")
            # Only what the base law reads changes the torque the residual is
            # added to; a raw-torque policy has no base law (as the Rust node).
            reads = set(self.law.keys) if self.law is not None else set()
            other = [k for k in sorted(set(trained) & set(run.params) & reads)
                     if k not in ESSENTIAL and k != "law" and _differs(trained[k], run.params[k], self.n)]
            if other:
                notes.append("this run's " + ", ".join(
                    f"controller.{k} = {quote(run.params[k])} (trained: {quote(trained[k])})" for k in other))
        for note in notes:
            print(f"testbed.policy_node: warning: {note}", file=sys.stderr, flush=True)

    def step(self, state: tc.State, ref: tc.Reference) -> np.ndarray:
        if state.seq == self.steps:
            # Past its episode the time feature exceeds 1: never seen in training.
            print(f"testbed.policy_node: warning: the run has passed the policy's episode of "
                  f"{self.steps} steps (env.steps); it acts on times it never saw",
                  file=sys.stderr, flush=True)
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
