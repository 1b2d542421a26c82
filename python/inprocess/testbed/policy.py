"""A linear policy on the environment's observation, a dependency-free
learner for it (random search), and its file: what a trained policy takes
back into `testbed compare` and a real-time run (`testbed.policy_node`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np

from ._native import SCENARIOS

try:  # Python 3.11 and later: an embedded scenario is checked before use.
    import tomllib
except ImportError:  # pragma: no cover
    tomllib = None

#: Longest value of a policy file quoted in a refusal.
QUOTE_CHARS = 80
#: Largest embedded scenario (env.scenario_toml), bytes.
MAX_SCENARIO_TOML = 1 << 20
#: Largest array of a policy file, bytes, by its zip entry's declared size
#: and by the shape its .npy header declares, both checked before any
#: array is read: a 2 MB zip bomb made numpy allocate 2 GiB before the
#: shapes were checked (#48 item 9). The widest arm (32 joints, 225
#: observations) needs 58 kB of weights.
MAX_POLICY_ARRAY_BYTES = 16 << 20


@dataclass
class LinearPolicy:
    """a = clip(W · obs + b, -1, 1), with the environment it was made for."""

    weights: np.ndarray
    bias: np.ndarray
    #: The environment's arguments (scenario, robot, set, duration,
    #: base_law, residual_scale, torque_scale, …) and its sizes (dof, steps).
    env: dict = field(default_factory=dict)

    @classmethod
    def zeros(cls, dof: int, obs_dim: int, env: Optional[dict] = None) -> "LinearPolicy":
        return cls(np.zeros((dof, obs_dim)), np.zeros(dof), dict(env or {}))

    def act(self, obs: np.ndarray) -> np.ndarray:
        return np.clip(self.weights @ obs + self.bias, -1.0, 1.0)

    def save(self, path) -> None:
        """Writes the policy as .npz (weights, bias, the environment as JSON)."""
        np.savez(path, weights=self.weights, bias=self.bias, env=json.dumps(self.env))

    def save_onnx(self, path) -> None:
        """Writes the policy as ONNX for the Rust node `testbed-policy`
        (needs the `onnx` package; see `testbed.onnx_export`)."""
        from .onnx_export import save_linear

        save_linear(self, path)

    @classmethod
    def load(cls, path) -> "LinearPolicy":
        _check_npz_sizes(path)
        with np.load(path, allow_pickle=False) as f:
            missing = {"weights", "bias", "env"} - set(f.files)
            if missing:
                raise ValueError(f"{path}: not a testbed policy file (no {', '.join(sorted(missing))})")
            weights, bias, env = f["weights"], f["bias"], json.loads(str(f["env"]))
        policy = cls(weights, bias, env)
        policy.check(str(path))
        return policy

    def check(self, where: str = "policy") -> None:
        """Refuses weights that do not fit the environment they name, or
        are not finite real numbers (ValueError naming the field)."""
        env = self.env
        if not isinstance(env, dict):
            raise ValueError(f"{where}: env is {type(env).__name__}, not a table of the environment")
        for key in ("dof", "obs_dim", "steps", "torque_scale"):
            if key not in env:
                raise ValueError(f"{where}: env.{key} is missing (save with testbed.policy.env_record)")
        dof, obs_dim, steps = env["dof"], env["obs_dim"], env["steps"]
        if not all(isinstance(x, int) and x >= 1 for x in (dof, obs_dim, steps)):
            raise ValueError(f"{where}: env.dof, env.obs_dim and env.steps must be integers ≥ 1")
        observe_action = env.get("observe_action", False)
        if not isinstance(observe_action, bool):
            raise ValueError(f"{where}: env.observe_action must be true or false")
        want = 7 * dof + 1 + (dof if observe_action else 0)
        if obs_dim != want:
            with_action = ", its last action observed," if observe_action else ""
            raise ValueError(f"{where}: env.obs_dim = {obs_dim}; an arm of {dof} joints{with_action} has {want}")
        smoothing = env.get("smoothing") or "hold"
        if smoothing not in ("hold", "ramp", "low-pass"):
            raise ValueError(f"{where}: env.smoothing = {smoothing!r}; it must be hold, ramp or low-pass")
        tau = env.get("smoothing_tau_s")
        if smoothing == "low-pass" and not (isinstance(tau, (int, float)) and not isinstance(tau, bool)
                                            and 0 < tau <= 1e3):
            raise ValueError(f"{where}: env.smoothing_tau_s = {tau!r}; a low-pass needs a time constant "
                             "in seconds above 0 and at most 1000")
        scale = np.asarray(env["torque_scale"])
        if scale.shape != (dof,) or not np.issubdtype(scale.dtype, np.number):
            raise ValueError(f"{where}: env.torque_scale must be {dof} numbers")
        # Files from before decimation and scaled observations: 1 kHz, raw.
        decimation = env.get("decimation", 1)
        if not (isinstance(decimation, int) and not isinstance(decimation, bool) and decimation >= 1):
            raise ValueError(f"{where}: env.decimation = {decimation!r}; it must be an integer ≥ 1")
        if not isinstance(env.get("scale_obs", False), bool):
            raise ValueError(f"{where}: env.scale_obs must be true or false")
        if env.get("scale_obs", False):
            v = np.asarray(env.get("velocity_scale", []))
            if v.shape != (dof,) or not np.issubdtype(v.dtype, np.number) or not np.all(v > 0):
                raise ValueError(f"{where}: env.velocity_scale must be {dof} positive numbers")
        w, b = np.asarray(self.weights), np.asarray(self.bias)
        if w.shape != (dof, obs_dim) or b.shape != (dof,):
            raise ValueError(f"{where}: weights {w.shape} and bias {b.shape}; "
                             f"this environment needs ({dof}, {obs_dim}) and ({dof},)")
        for name, x in (("weights", w), ("bias", b), ("env.torque_scale", scale)):
            if not np.issubdtype(x.dtype, np.floating) and not np.issubdtype(x.dtype, np.integer):
                raise ValueError(f"{where}: {name} has dtype {x.dtype}, not real numbers")
            if not np.all(np.isfinite(x)):
                raise ValueError(f"{where}: {name} has a value that is not finite")
        check_scenario(env, where)
        self.weights, self.bias = w.astype(np.float64), b.astype(np.float64)


def _check_npz_sizes(path) -> None:
    """Refuses a policy file whose arrays would be larger than
    MAX_POLICY_ARRAY_BYTES, from the zip's directory and each .npy header
    alone (ValueError naming the file, the member and the cap)."""
    import zipfile

    cap = MAX_POLICY_ARRAY_BYTES
    try:
        archive = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError) as e:
        raise ValueError(f"{path}: not a testbed policy file (not a readable .npz: {quote(str(e))})") from None
    with archive:
        for info in archive.infolist():
            name = quote(info.filename)
            if info.file_size > cap:
                raise ValueError(f"{path}: member {name} is {info.file_size} bytes unpacked, "
                                 f"over the cap of {cap} bytes on a policy array")
            if not info.filename.endswith(".npy"):
                continue
            with archive.open(info) as member:
                try:
                    version = np.lib.format.read_magic(member)
                    header = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                              else np.lib.format.read_array_header_2_0)
                    shape, _, dtype = header(member)
                except (ValueError, OSError) as e:
                    raise ValueError(f"{path}: member {name} has no readable .npy header "
                                     f"({quote(str(e))})") from None
            count = 1
            for n in shape:
                count *= n
            if count * max(dtype.itemsize, 1) > cap:
                raise ValueError(f"{path}: member {name} declares shape {quote(shape)} of {dtype}, "
                                 f"over the cap of {cap} bytes on a policy array")


def quote(value) -> str:
    """A value of a policy file as a refusal shows it: repr, cut short."""
    text = repr(value)
    return text if len(text) <= QUOTE_CHARS else text[:QUOTE_CHARS] + "…"


def _names_a_file(key: str) -> bool:
    """A scenario key (dotted) whose value is a path: `robot`, a trajectory `file`."""
    return key == "robot" or key.rsplit(".", 1)[-1] == "file"


def _file_keys(table: dict, prefix: str = ""):
    for k, v in table.items():
        key = f"{prefix}{k}"
        if _names_a_file(key):
            yield key
        if isinstance(v, dict):
            yield from _file_keys(v, key + ".")


def check_scenario(env: dict, where: str) -> None:
    """Refuses a policy whose scenario the testbed would have to read from
    a file the policy names (issue 48, N2: env.scenario = "/etc/passwd" put
    that file's first line into stderr, the controller's log and `compare
    --json`). A policy names a shipped scenario (`testbed.SCENARIOS`) or
    embeds its own (env.scenario_toml) holding no path; env.robot must be
    a `.urdf` or MJCF `.xml` file, whose errors are never quoted (see policy_node)."""
    scenario, text = env.get("scenario"), env.get("scenario_toml")
    if scenario is not None and text is not None:
        raise ValueError(f"{where}: env.scenario and env.scenario_toml are both set; a policy has one scenario")
    if scenario is not None and (not isinstance(scenario, str) or scenario not in SCENARIOS):
        raise ValueError(f"{where}: env.scenario = {quote(scenario)} is not a shipped scenario "
                         f"({', '.join(SCENARIOS)}); a policy names one of those or embeds its own "
                         "as env.scenario_toml, and no other file is read")
    if text is not None:
        if not isinstance(text, str) or len(text.encode("utf-8", "replace")) > MAX_SCENARIO_TOML:
            raise ValueError(f"{where}: env.scenario_toml must be the scenario's TOML text, "
                             f"at most {MAX_SCENARIO_TOML} bytes")
        if tomllib is None:
            raise ValueError(f"{where}: env.scenario_toml needs Python 3.11 or later to be checked")
        try:
            table = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            raise ValueError(f"{where}: env.scenario_toml is not TOML: {e}") from None
        for key in _file_keys(table):
            raise ValueError(f"{where}: env.scenario_toml sets {key}, which names a file; an embedded "
                             "scenario holds its data (a trajectory as samples, the robot as env.robot)")
    robot = env.get("robot")
    if robot is not None and not (isinstance(robot, str) and robot.endswith((".urdf", ".xml"))
                                  and len(robot) <= 4096):
        raise ValueError(f"{where}: env.robot = {quote(robot)} is not a path to a .urdf or MJCF .xml file")
    overrides = env.get("set")
    if overrides is None:
        return
    if isinstance(overrides, str):
        overrides = [overrides]
    if not isinstance(overrides, (list, tuple)) or not all(isinstance(o, str) for o in overrides):
        raise ValueError(f"{where}: env.set must be a list of \"key=value\" texts")
    for o in overrides:
        key = o.split("=", 1)[0].strip()
        if _names_a_file(key):
            raise ValueError(f"{where}: env.set sets {quote(key)}, which names a file; a policy file "
                             "names no file but env.robot")


def env_record(env) -> dict:
    """What a policy file keeps of an `ArmTrackingEnv`: its sizes, and what
    `testbed.policy_node` needs to act as the environment does (plant
    periods per decision, the torque and velocity scales, whether the
    observation is scaled)."""
    core = env.unwrapped.core
    record = {"dof": core.dof, "obs_dim": core.obs_dim, "steps": core.steps,
              "torque_scale": core.torque_scale.tolist(), "decimation": core.decimation,
              "scale_obs": core.scale_obs, "velocity_scale": core.velocity_scale.tolist(),
              "smoothing": core.smoothing, "smoothing_tau_s": core.smoothing_tau_s,
              "observe_action": core.observe_action,
              # What `policy_node` checks against the run it is put in.
              "period_ns": round(core.plant_dt * 1e9)}
    if tomllib is not None:
        record["controller"] = tomllib.loads(core.scenario_toml).get("controller", {})
    return record


def episode_return(env, policy: LinearPolicy, seed: int) -> float:
    """The undiscounted return of one episode from reset(seed=seed)."""
    obs, _ = env.reset(seed=seed)
    total, done = 0.0, False
    while not done:
        obs, reward, terminated, truncated, _ = env.step(policy.act(obs))
        total += reward
        done = terminated or truncated
    return total


def random_search(env, policy: LinearPolicy, *, iterations: int = 10, directions: int = 8,
                  top: int = 4, step_size: float = 0.02, noise: float = 0.03, seed: int = 0,
                  episode_seed: int = 0,
                  callback: Optional[Callable[[int, float], None]] = None) -> LinearPolicy:
    """Augmented random search (Mania et al. 2018, V1-t) on the weights:
    each iteration tries `directions` random perturbations both ways on the
    episode of `episode_seed` and moves along the best `top` of them."""
    rng = np.random.default_rng(seed)
    params = np.concatenate([policy.weights, policy.bias[:, None]], axis=1)

    def ret(p):
        trial = LinearPolicy(p[:, :-1], p[:, -1], policy.env)
        return episode_return(env, trial, episode_seed)

    for it in range(iterations):
        deltas = rng.standard_normal((directions,) + params.shape)
        plus = np.array([ret(params + noise * d) for d in deltas])
        minus = np.array([ret(params - noise * d) for d in deltas])
        best = np.argsort(-np.maximum(plus, minus))[:top]
        sigma = np.concatenate([plus[best], minus[best]]).std() or 1.0
        step = sum((plus[k] - minus[k]) * deltas[k] for k in best)
        params = params + step_size / (top * sigma) * step
        if callback is not None:
            callback(it, ret(params))
    return LinearPolicy(params[:, :-1].copy(), params[:, -1].copy(), policy.env)
