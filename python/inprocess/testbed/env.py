"""The Gymnasium environments: `testbed/ArmTracking-v0` and its vector form.

A step is one decision of the agent: its action acts for `decimation`
plant periods (held, ramped or low-pass filtered: `smoothing`) (default 20 of the paper's 1 ms: a 50 Hz policy) and becomes
the joint torques, or a residual on a built-in law; the arm (the testbed's
plant, with every effect the scenario turns on) steps, and the environment
returns the next observation, a tracking reward, and, in `info["cost"]`,
whether the deferred constraint |e_i| < k_c,i(t) was broken after T_c. The
loop runs in Rust (the `gym-env` crate, through `testbed._native`);
docs/python.md has the whole contract.
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

#: The render modes: None (no picture) or "rgb_array".
RENDER_MODES = ["rgb_array"]

#: The side of a rendered picture, pixels.
RENDER_SIZE = 480


def observation_names(dof: int, observe_action: bool = False) -> list:
    """The observation's entries by name: e0, e1, …, kc{n-1}, time_fraction,
    then a0, …, a{n-1} (the last action) with `observe_action`."""
    names = [f"{p}{i}" for p in OBSERVATION for i in range(dof)] + ["time_fraction"]
    return names + ([f"a{i}" for i in range(dof)] if observe_action else [])


def _spaces(core):
    obs = spaces.Box(-np.inf, np.inf, shape=(core.obs_dim,), dtype=np.float64)
    act = spaces.Box(-1.0, 1.0, shape=(core.dof,), dtype=np.float32)
    return obs, act


def _seed_from(rng: np.random.Generator) -> int:
    return int(rng.integers(0, 2**63 - 1))


def _real_actions(actions, what: str = "step: action"):
    """The actions as given, unless they would be read silently wrong:
    complex (its imaginary part dropped), bool (True as 1.0) or float16
    (an action rounded to 3 digits) raise TypeError naming the dtype.
    Anything else goes on to the usual checks (strings and bytes are
    refused there as not numbers)."""
    dtype = getattr(actions, "dtype", None)
    if dtype is None:
        dtype = np.asarray(actions).dtype
    why = {"c": "complex: its imaginary part would be dropped",
           "b": "bool: True would be read as 1.0"}.get(dtype.kind)
    if dtype.kind == "f" and dtype.itemsize < 4:
        why = "float16: the action would be rounded to 3 significant digits"
    if why:
        raise TypeError(f"{what}: dtype {dtype} is refused ({why}); give float32 or float64")
    return actions


def _render_mode(render_mode):
    if render_mode is not None and render_mode not in RENDER_MODES:
        raise ValueError(f"render_mode = {render_mode!r}: the modes are None and 'rgb_array'")
    return render_mode


def _check_open(env, what: str) -> None:
    if env._closed:
        raise RuntimeError(f"{what}() after close(): make a new environment")


def _close(env) -> None:
    env._closed = True


def _one_at_a_time(call, *args):
    """A core call, with PyO3's bare "Already borrowed" (another thread is
    inside a call of this environment) said as what to do instead."""
    try:
        return call(*args)
    except RuntimeError as e:
        if "borrow" not in str(e).lower():
            raise
        raise RuntimeError(
            "this environment is inside a call from another thread: an environment takes one "
            "call at a time; give each thread its own environment (or hold a lock around "
            "reset/step)") from None


class ArmTrackingEnv(gymnasium.Env):
    """Track a scenario's reference with an arm under its deferred constraint.

    Arguments (all optional, docs/python.md has units and defaults):
    `scenario`, `robot`, `set`, `episode_s` (default 4 s; `duration` is its
    old name), `decimation` (default 20 plant periods per decision),
    `base_law` (None: the action is the torque; a law's name: a residual on
    it), `residual_scale` (0.2), `torque_scale` (default derived from the
    arm), `effort_weight` (0.01), `breach_factor` (2; None: never end
    early), `safe` (False), `scale_obs` (True), `smoothing` ("hold";
    "ramp" or "low-pass"), `smoothing_tau_s` (0.02, the low-pass's),
    `action_rate_weight` (0), `observe_action` (False), `render_mode` (None
    or "rgb_array").

    - action: n numbers in [-1, 1] (clipped), float32; τ_i = a_i · scale_i,
      or τ = τ_law + a_i · residual_scale · scale_i, over `decimation`
      plant periods: held, ramped from the last decision's torque, or
      low-pass filtered (`smoothing`).
    - observation: float64, 7n + 1 numbers: e/k_c, ė/v, q, q̇/v, q_d,
      q̇_d/v, k_c, t / T, v the velocity scale (`scale_obs=False`: e, ė, q,
      q̇, q_d, q̇_d, k_c, t / T unscaled; `observation_names`), then the
      last clipped action with `observe_action` (8n + 1).
    - reward: the mean over the held periods of −mean_i min((e_i/k_c,i)²,
      100) − effort_weight · mean_i a_i² − action_rate_weight · mean_i
      (a_i − a_i,prev)²; an early end adds the worst reward (−100 −
      effort_weight − 4 · action_rate_weight) for every decision it skips.
    - info["cost"]: 1.0 when, at or after T_c, some |e_i| ≥ k_c,i after a
      held period; else 0.
    - terminated: the state is not finite, or (not safe) some |e_i| >
      breach_factor · k_c,i after T_c. truncated: the episode's end.
    - reset(seed=s, options={"initial_q": [...], "initial_qd": [...]}):
      the scenario's `[randomise]` table drawn with seed s, the plant's
      noise seeded by it; without a seed, one drawn from the env's RNG.
    """

    metadata = {"render_modes": RENDER_MODES, "render_fps": 50}

    def __init__(self, scenario=None, *, render_mode=None, **kwargs):
        self.render_mode = _render_mode(render_mode)
        self._core = EnvCore(scenario, **kwargs)
        self.observation_space, self.action_space = _spaces(self._core)
        self.metadata = dict(self.metadata, render_fps=max(1, int(round(1.0 / self._core.dt))))
        self._ended = True
        self._fresh = True
        self._closed = False

    @property
    def core(self) -> EnvCore:
        """The Rust core (dt, decimation, steps, tc, joint_names, torque_scale, true_state…)."""
        return self._core

    def reset(self, *, seed=None, options=None):
        _check_open(self, "reset")
        super().reset(seed=seed)
        if options is not None and not isinstance(options, dict):
            raise TypeError(f"reset: options must be a dict, got {type(options).__name__}")
        episode_seed = seed if seed is not None else _seed_from(self.np_random)
        obs = _one_at_a_time(self._core.reset, int(episode_seed), options or None)
        self._ended = False
        self._fresh = False
        return obs, {"seed": int(episode_seed)}

    def step(self, action):
        _check_open(self, "step")
        if self._fresh:
            raise RuntimeError("step() before reset(): call reset() first (Gymnasium's order)")
        if self._ended:
            raise RuntimeError("step() after the episode ended: call reset() first")
        out = _one_at_a_time(self._core.step, _real_actions(action))
        self._ended = out[2] or out[3]
        return out

    def render(self):
        """The arm (dark, joints red) over its reference pose (light), as an
        (480, 480, 3) uint8 array with render_mode="rgb_array"; else None."""
        if self.render_mode == "rgb_array":
            return self._core.render(RENDER_SIZE, RENDER_SIZE)
        return None

    def close(self):
        """Ends the environment: a later step or reset raises."""
        _close(self)
        super().close()


class ArmTrackingVecEnv(gymnasium.vector.VectorEnv):
    """`num_envs` arms of one scenario stepped in Rust in one call.

    The same arguments and contract as `ArmTrackingEnv`, batched: actions
    of shape (num_envs, n) (any memory order), observations (num_envs,
    7n + 1, or 8n + 1 with `observe_action`), rewards, terminated and truncated of shape (num_envs,), and
    `info["cost"]`. An arm whose episode ended resets on the next step
    (Gymnasium's NEXT_STEP autoreset: that step ignores its action and
    returns its first observation, reward 0). `reset(seed=s, options=…)`
    gives arm i the seed s + i; `options` as the single env's (`initial_q`,
    `initial_qd`: n numbers for every arm, or (num_envs, n), a row per
    arm), for that reset only. `render()` gives one picture per arm.
    `num_threads` (default: every CPU) is how many threads step the arms;
    the results are the same bits whatever it is.
    """

    metadata = {"autoreset_mode": gymnasium.vector.AutoresetMode.NEXT_STEP,
                "render_modes": RENDER_MODES}

    def __init__(self, num_envs: int = 1, scenario=None, *, render_mode=None, **kwargs):
        self.render_mode = _render_mode(render_mode)
        self._core = VecEnvCore(operator.index(num_envs), scenario, **kwargs)
        self.num_envs = self._core.num_envs
        self.single_observation_space, self.single_action_space = _spaces(self._core)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.metadata = dict(self.metadata, render_fps=max(1, int(round(1.0 / self._core.dt))))
        self._all = np.ones(self.num_envs, dtype=bool)
        self._fresh = True
        self._closed = False

    @property
    def core(self) -> VecEnvCore:
        """The Rust core."""
        return self._core

    def reset(self, *, seed=None, options=None):
        _check_open(self, "reset")
        if options is not None and not isinstance(options, dict):
            raise TypeError(f"reset: options must be a dict, got {type(options).__name__}")
        if seed is not None and not isinstance(seed, (int, np.integer)):
            seeds = [operator.index(s) for s in seed]
            if not seeds or seeds != [seeds[0] + i for i in range(self.num_envs)]:
                raise ValueError("reset: seed must be an int s (arm i gets s + i), or [s, s+1, …]")
            seed = seeds[0]
        super().reset(seed=seed)
        if seed is None:
            seed = _seed_from(self.np_random)
        obs = _one_at_a_time(self._core.reset, int(seed), options or None)
        self._fresh = False
        return obs, {}

    def step(self, actions):
        _check_open(self, "step")
        if self._fresh:
            raise RuntimeError("step() before reset(): call reset() first (Gymnasium's order)")
        actions = np.asarray(_real_actions(actions, "step: actions"), dtype=np.float64)
        obs, rewards, terminated, truncated, costs = _one_at_a_time(self._core.step, actions)
        return obs, rewards, terminated, truncated, {"cost": costs, "_cost": self._all}

    def render(self):
        """One picture per arm with render_mode="rgb_array"; else None."""
        if self.render_mode != "rgb_array":
            return None
        return tuple(self._core.render(i, RENDER_SIZE, RENDER_SIZE) for i in range(self.num_envs))

    def close(self, **kwargs):
        """Ends the environment: a later step or reset raises."""
        _close(self)
        super().close(**kwargs)
