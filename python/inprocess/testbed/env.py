"""The Gymnasium environments: `testbed/ArmTracking-v0` and its vector form.

A step is one control period of a scenario (1 ms in the paper's): the
agent's action becomes the joint torques, or a residual on a built-in law,
the arm (the testbed's plant, with every effect the scenario turns on) steps
one period, and the environment returns the next observation, a tracking
reward, and, in `info["cost"]`, whether the constraint |e_i| < k_c,i(t) was
broken (Safety-Gymnasium's convention). The loop runs in Rust
(`testbed._native`); docs/python.md has the whole contract.
"""

from __future__ import annotations

import operator

import numpy as np
import gymnasium
from gymnasium import spaces
from gymnasium.vector.utils import batch_space

from ._native import EnvCore, VecEnvCore

#: The observation's parts, in order; each has one entry per joint, except
#: the time fraction t / T.
OBSERVATION = ("e", "e_dot", "q", "qd", "q_d", "qd_d", "kc")


def observation_names(dof: int) -> list:
    """The observation's entries by name: e0, e1, …, kc{n-1}, time_fraction."""
    return [f"{p}{i}" for p in OBSERVATION for i in range(dof)] + ["time_fraction"]


def _spaces(core):
    obs = spaces.Box(-np.inf, np.inf, shape=(core.obs_dim,), dtype=np.float64)
    act = spaces.Box(-1.0, 1.0, shape=(core.dof,), dtype=np.float32)
    return obs, act


def _seed_from(rng: np.random.Generator) -> int:
    return int(rng.integers(0, 2**63 - 1))


class ArmTrackingEnv(gymnasium.Env):
    """Track a scenario's reference with an arm under its deferred constraint.

    Arguments (all optional): `scenario` (a file or a shipped name; default
    the paper's), `robot` (a URDF; alone, its default scenario), `set`
    (`--set` overrides, a dict or "key=value" strings), `duration` (s),
    `base_law` (None: the action is the torque; a law's name: a residual
    on it), `residual_scale` (the residual's span as a fraction of the
    torque scale, default 0.2), `effort_weight` (default 0.01),
    `breach_factor` (end the episode once, after T_c, an error passes this
    many times its envelope; default 2, None: never), `torque_scale` (torque
    per unit of action; default the effort limits).

    - action: n numbers in [-1, 1] (clipped), float32; τ_i = a_i · scale_i,
      or τ = τ_law + a_i · residual_scale · scale_i.
    - observation: float64, 7n + 1 numbers: e = q − q_d, ė = q̇ − q̇_d, q,
      q̇ (as measured), q_d, q̇_d, k_c, t / T (`observation_names`).
    - reward: −mean_i (e_i / k_c,i)² − effort_weight · mean_i (τ_i / scale_i)²,
      with the true error after the step.
    - info["cost"]: 1.0 when, at or after T_c, some |e_i| ≥ k_c,i; else 0.
    - terminated: the state is not finite (reward −100), or breached.
    - truncated: the scenario's end (duration_s).
    - reset(seed=s): the scenario's `[randomise]` table drawn with seed s,
      and the plant's noise seeded by it (the run of `testbed sim --set
      seed=s`); without a seed, one is drawn from the environment's RNG.
    """

    metadata = {"render_modes": [], "render_fps": 1000}

    def __init__(self, scenario=None, *, render_mode=None, **kwargs):
        if render_mode is not None:
            raise ValueError("ArmTrackingEnv has no render mode; watch a run in Foxglove instead")
        self._core = EnvCore(scenario, **kwargs)
        self.observation_space, self.action_space = _spaces(self._core)
        self.metadata = dict(self.metadata, render_fps=int(round(1.0 / self._core.dt)))
        self._ended = True

    @property
    def core(self) -> EnvCore:
        """The Rust core (dt, steps, tc, joint_names, torque_scale, true_state…)."""
        return self._core

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        if options:
            raise ValueError(f"reset: options {sorted(options)} are not taken; pass seed= only")
        episode_seed = seed if seed is not None else _seed_from(self.np_random)
        obs = self._core.reset(int(episode_seed))
        self._ended = False
        return obs, {"seed": int(episode_seed)}

    def step(self, action):
        if self._ended:
            raise RuntimeError("step() after the episode ended: call reset() first")
        out = self._core.step(action)
        self._ended = out[2] or out[3]
        return out


class ArmTrackingVecEnv(gymnasium.vector.VectorEnv):
    """`num_envs` arms of one scenario stepped in Rust in one call.

    The same arguments and contract as `ArmTrackingEnv`, batched: actions
    of shape (num_envs, n), observations (num_envs, 7n + 1), rewards,
    terminated and truncated of shape (num_envs,), and `info["cost"]`.
    An arm whose episode ended resets on the next step (Gymnasium's
    NEXT_STEP autoreset: that step ignores its action and returns its first
    observation, reward 0). `reset(seed=s)` gives arm i the seed s + i.
    """

    metadata = {"autoreset_mode": gymnasium.vector.AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs: int = 1, scenario=None, *, render_mode=None, **kwargs):
        if render_mode is not None:
            raise ValueError("ArmTrackingVecEnv has no render mode")
        self._core = VecEnvCore(operator.index(num_envs), scenario, **kwargs)
        self.num_envs = self._core.num_envs
        self.single_observation_space, self.single_action_space = _spaces(self._core)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._all = np.ones(self.num_envs, dtype=bool)

    @property
    def core(self) -> VecEnvCore:
        """The Rust core."""
        return self._core

    def reset(self, *, seed=None, options=None):
        if options:
            raise ValueError(f"reset: options {sorted(options)} are not taken; pass seed= only")
        if seed is not None and not isinstance(seed, (int, np.integer)):
            seeds = [operator.index(s) for s in seed]
            if not seeds or seeds != [seeds[0] + i for i in range(self.num_envs)]:
                raise ValueError("reset: seed must be an int s (arm i gets s + i), or [s, s+1, …]")
            seed = seeds[0]
        super().reset(seed=seed)
        if seed is None:
            seed = _seed_from(self.np_random)
        obs = self._core.reset(int(seed))
        return obs, {}

    def step(self, actions):
        actions = np.ascontiguousarray(actions, dtype=np.float64)
        obs, rewards, terminated, truncated, costs = self._core.step(actions)
        return obs, rewards, terminated, truncated, {"cost": costs, "_cost": self._all}
