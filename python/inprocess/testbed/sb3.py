"""Stable-Baselines3's VecEnv over the Rust vector form.

    from testbed.sb3 import ArmTrackingSB3VecEnv
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecMonitor

    venv = VecMonitor(ArmTrackingSB3VecEnv(64, base_law="pd"))
    model = PPO("MlpPolicy", venv)
    model.set_logger(silent_logger())  # else SB3 leaves /tmp/SB3-<date>/
    model.learn(100_000)

The arms step in Rust in one call, on every CPU (`num_threads`), as in
`testbed.ArmTrackingVecEnv`; this class only speaks SB3's protocol:
`step_async`/`step_wait` returning `(obs, rewards, dones, infos)`, an arm
whose episode ended reset in the same step (its last observation in
`infos[i]["terminal_observation"]`, `infos[i]["TimeLimit.truncated"]` for
a time limit), `seed()`/`set_options()` applied at the next `reset()`,
`get_attr`/`set_attr`/`env_method` on per-arm views, and `render()` for
`VecVideoRecorder`. `infos[i]["cost"]` is the safety cost.

Stable-Baselines3 is imported here, not by `import testbed`:
`pip install stable-baselines3` (or the package's `train` extra).
"""

from __future__ import annotations

import operator

import numpy as np

try:
    from stable_baselines3.common.vec_env.base_vec_env import VecEnv
except ImportError as e:  # pragma: no cover - the message is the point
    raise ImportError("testbed.sb3 needs Stable-Baselines3: pip install stable-baselines3") from e

from ._native import VecEnvCore
from .env import RENDER_MODES, RENDER_SIZE, _real_actions, _render_mode, _spaces

__all__ = ["ArmTrackingSB3VecEnv", "silent_logger"]


def silent_logger():
    """An SB3 logger that writes nothing anywhere. Without a logger of its
    own (or a `tensorboard_log`), every `learn()` makes an empty folder
    /tmp/SB3-<date>/ that nothing removes."""
    from stable_baselines3.common.logger import Logger

    return Logger(folder=None, output_formats=[])


class _Arm:
    """One arm as `get_attr`, `set_attr` and `env_method` see it: the
    single environment's attributes (spaces, render_mode, metadata, the
    arm's current seed) and `render()`; attributes set on it stay on it."""

    def __init__(self, parent: "ArmTrackingSB3VecEnv", index: int):
        self._parent = parent
        self._index = index
        self.observation_space = parent.observation_space
        self.action_space = parent.action_space
        self.render_mode = parent._render_mode_arg
        self.metadata = parent._arm_metadata

    @property
    def core(self) -> VecEnvCore:
        """The vector's Rust core (shared by every arm)."""
        return self._parent.core

    @property
    def seed(self) -> int:
        """The seed of the arm's current episode."""
        return self._parent.core.seeds[self._index]

    @property
    def unwrapped(self) -> "_Arm":
        return self

    def render(self):
        """The arm's picture, (480, 480, 3) uint8, with render_mode="rgb_array"; else None."""
        if self.render_mode != "rgb_array":
            return None
        return self._parent.core.render(self._index, RENDER_SIZE, RENDER_SIZE)


class ArmTrackingSB3VecEnv(VecEnv):
    """`num_envs` arms of `testbed/ArmTracking-v0` as an SB3 VecEnv.

    Takes the keywords of `testbed.ArmTrackingVecEnv` (`scenario`,
    `robot`, `set`, `episode_s`, `decimation`, `base_law`, …,
    `num_threads`, `render_mode`). Arm i's first episode after
    `seed(s)` + `reset()` is the Gymnasium vector form's after
    `reset(seed=s)`, and every later one too: the same seeds, the same
    steps, only the reset step of Gymnasium's NEXT_STEP autoreset folded
    into the step that ended the episode (a test checks it bit for bit).
    Without `seed()`, `reset()` draws a seed from NumPy's global RNG.
    """

    def __init__(self, num_envs: int = 1, scenario=None, *, render_mode=None, **kwargs):
        self._render_mode_arg = _render_mode(render_mode)
        self._core = VecEnvCore(operator.index(num_envs), scenario, **kwargs)
        observation_space, action_space = _spaces(self._core)
        self.observation_space, self.action_space = observation_space, action_space
        fps = max(1, int(round(1.0 / self._core.dt)))
        self._arm_metadata = {"render_modes": RENDER_MODES, "render_fps": fps}
        self._arms = [_Arm(self, i) for i in range(self._core.num_envs)]
        self._actions = None
        super().__init__(self._core.num_envs, observation_space, action_space)
        # SB3's base sets its own metadata from the render mode; the
        # decision rate is what VecVideoRecorder reads.
        self.metadata = dict(self.metadata, render_fps=fps)

    @property
    def core(self) -> VecEnvCore:
        """The Rust core (num_threads, seeds, torque_scale, dt, …)."""
        return self._core

    # -- SB3's protocol ---------------------------------------------------

    def reset(self):
        seeds = [s for s in self._seeds if s is not None]
        if seeds and len(seeds) == self.num_envs:
            first = int(seeds[0])
            if [int(s) for s in seeds] != [first + i for i in range(self.num_envs)]:
                raise ValueError("reset: the vector form gives arm i the seed s + i; "
                                 "seed with venv.seed(s)")
        elif seeds:
            raise ValueError("reset: seeds for some arms only; seed with venv.seed(s)")
        else:
            first = int(np.random.randint(0, np.iinfo(np.uint32).max, dtype=np.uint32))
        obs = self._core.reset(first, self._reset_options_dict())
        self.reset_infos = [{"seed": first + i} for i in range(self.num_envs)]
        self._reset_seeds()
        self._reset_options()
        return obs

    def _reset_options_dict(self):
        """SB3 keeps one options dict per arm: the same for all, or rows."""
        opts = self._options
        if all(not o for o in opts):
            return None
        keys = set().union(*opts)
        out = {}
        for k in keys:
            values = [o.get(k) for o in opts]
            if any(v is None for v in values):
                raise ValueError(f"reset: option '{k}' given for some arms only")
            out[k] = np.asarray(values, dtype=np.float64)
        return out

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(_real_actions(actions, "step_async: actions"), dtype=np.float64)

    def step_wait(self):
        if self._actions is None:
            raise RuntimeError("step_wait() without step_async()")
        actions, self._actions = self._actions, None
        obs, rewards, terminated, truncated, costs, final = self._core.step_same(actions)
        dones = terminated | truncated
        infos = [{"cost": float(c)} for c in costs]
        for i in np.flatnonzero(dones):
            infos[i]["terminal_observation"] = final[i]
            infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        return obs, rewards.astype(np.float32), dones, infos

    def close(self) -> None:
        pass

    def get_images(self):
        return [arm.render() for arm in self._arms]

    # -- per-arm views --------------------------------------------------

    def _views(self, indices):
        return [self._arms[i] for i in self._get_indices(indices)]

    def get_attr(self, attr_name: str, indices=None) -> list:
        return [getattr(arm, attr_name) for arm in self._views(indices)]

    def set_attr(self, attr_name: str, value, indices=None) -> None:
        for arm in self._views(indices):
            setattr(arm, attr_name, value)

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs) -> list:
        return [getattr(arm, method_name)(*method_args, **method_kwargs) for arm in self._views(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None) -> list:
        # The arms are Rust, not gymnasium.Env instances: no wrapper wraps one.
        return [False for _ in self._views(indices)]
