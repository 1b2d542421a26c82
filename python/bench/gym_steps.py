"""Environment steps a second from Python: the testbed's Gymnasium
environment (one arm; 64 arms in one vector call, on one thread and on
every CPU) beside Gymnasium's MuJoCo Reacher-v5, in one run, medians of
--repeats.

    python python/bench/gym_steps.py [--repeats 5] [--steps 200000] [--json]
    python python/bench/gym_steps.py --only-threads    (the vector form's threads only)
    testbed bench --gym        (the same, with target/python-venv's python)

The vector form's one-thread and all-CPU figures are taken in turns, one
of each per repeat, so that load from elsewhere on the machine falls on
both alike; the ratio printed is of their medians.

Needs the module built (`bash python/build-module.sh --release` for
figures that mean anything) and, for the peer, MuJoCo
(`bash python/setup-venv.sh --peer`).
"""

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path

import gymnasium
import numpy as np

import testbed

ROOT = Path(__file__).resolve().parents[2]

#: One plant period a step, the raw observation: the step these figures
#: have always counted (the environment's default holds an action 20
#: periods; `env_two_link_decisions` counts those).
PERIOD = {"decimation": 1, "scale_obs": False}


def single(make, steps):
    env = make()
    env.reset(seed=0)
    action = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    step, reset = env.step, env.reset
    start = time.perf_counter()
    for _ in range(steps):
        _, _, term, trunc, _ = step(action)
        if term or trunc:
            reset()
    return steps / (time.perf_counter() - start)


def vector(num, steps, **kwargs):
    venv = gymnasium.make_vec(testbed.ENV_ID, num_envs=num, **kwargs)
    venv.reset(seed=0)
    actions = np.zeros((num,) + venv.single_action_space.shape)
    calls = max(1, steps // num)
    step = venv.step
    start = time.perf_counter()
    for _ in range(calls):
        step(actions)
    return calls * num / (time.perf_counter() - start)


def reacher():
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return None
    return lambda: gymnasium.make("Reacher-v5")


def median_of(fn, repeats):
    runs = [fn() for _ in range(repeats)]
    return {"median": statistics.median(runs), "runs": runs}


def in_turns(fns, repeats):
    """Each of `fns` once per repeat, in turns: their medians."""
    runs = {k: [] for k in fns}
    for _ in range(repeats):
        for k, fn in fns.items():
            runs[k].append(fn())
    return {k: {"median": statistics.median(r), "runs": r} for k, r in runs.items()}


def threads_figures(a, iiwa):
    """64 arms on one thread and on every CPU (num_threads=None), in turns."""
    # The CPUs this process may run on: what num_threads=None uses.
    cpus = len(os.sched_getaffinity(0))
    figures = in_turns({
        "vec64_two_link_1thread": lambda: vector(64, a.steps, num_threads=1, **PERIOD),
        "vec64_two_link": lambda: vector(64, a.steps, **PERIOD),
        "vec64_two_link_decisions_1thread": lambda: vector(64, a.steps // 20, num_threads=1),
        "vec64_two_link_decisions": lambda: vector(64, a.steps // 20),
        "vec64_iiwa14_1thread": lambda: vector(64, a.steps // 4, robot=iiwa, num_threads=1, **PERIOD),
        "vec64_iiwa14": lambda: vector(64, a.steps // 4, robot=iiwa, **PERIOD),
    }, a.repeats)
    return figures, cpus


THREAD_ROWS = [
    ("vector env, 64 two-link arms, arm-steps, 1 thread", "vec64_two_link_1thread", "vec64_two_link"),
    ("the same, default decimation 20: arm-decisions, 1 thread", "vec64_two_link_decisions_1thread",
     "vec64_two_link_decisions"),
    ("vector env, 64 iiwa14 arms, arm-steps, 1 thread", "vec64_iiwa14_1thread", "vec64_iiwa14"),
]


def print_figure(label, f):
    if f is None:
        print(f"  {label:58s} not measured (MuJoCo not installed: bash python/setup-venv.sh --peer)")
    else:
        lo, hi = min(f["runs"]), max(f["runs"])
        print(f"  {label:58s} {f['median']:12,.0f}  ({lo:,.0f}–{hi:,.0f})")


def print_threads(figures, cpus):
    for label, one, many in THREAD_ROWS:
        print_figure(label, figures[one])
        print_figure(f"  on every CPU ({cpus})", figures[many])
        print(f"  {'  every CPU / 1 thread':58s} {figures[many]['median'] / figures[one]['median']:12.2f}×")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--steps", type=int, default=200_000, help="steps per measurement")
    p.add_argument("--json", action="store_true")
    p.add_argument("--only-threads", action="store_true",
                   help="only the vector form on one thread and on every CPU")
    a = p.parse_args()
    if a.repeats < 1 or a.steps < 20:
        p.error("--repeats must be at least 1 and --steps at least 20")
    iiwa = str(ROOT / "robots/iiwa14.urdf")
    thread_figures, cpus = threads_figures(a, iiwa)
    if a.only_threads:
        if a.json:
            print(json.dumps({"cpus": cpus, "steps": a.steps, "repeats": a.repeats,
                              "module_build": testbed._native.__file__, "figures": thread_figures}))
        else:
            print(f"arm-steps a second, {cpus} CPUs, medians of {a.repeats}:")
            print_threads(thread_figures, cpus)
        return
    figures = {
        "env_two_link": median_of(
            lambda: single(lambda: gymnasium.make(testbed.ENV_ID, **PERIOD), a.steps), a.repeats),
        "env_two_link_decisions": median_of(
            lambda: single(lambda: gymnasium.make(testbed.ENV_ID), max(1, a.steps // 20)), a.repeats),
        **thread_figures,
    }
    peer = reacher()
    figures["reacher_v5"] = (median_of(lambda: single(peer, a.steps), a.repeats)
                             if peer else None)
    result = {
        "python": platform.python_version(),
        "cpus": cpus,
        "gymnasium": gymnasium.__version__,
        "module_build": testbed._native.__file__,
        "steps": a.steps,
        "repeats": a.repeats,
        "figures": figures,
    }
    if a.json:
        print(json.dumps(result))
        return
    rows = [("testbed/ArmTracking-v0, two-link arm, env.step (one 1 ms period)", "env_two_link"),
            ("the same, default decimation 20: decisions", "env_two_link_decisions"),
            ("Gymnasium MuJoCo Reacher-v5, env.step (peer)", "reacher_v5")]
    print(f"steps a second from Python {result['python']}, Gymnasium {result['gymnasium']}: "
          f"medians of {a.repeats}")
    for label, key in rows:
        print_figure(label, figures[key])
    print_threads(figures, cpus)
    if figures["reacher_v5"]:
        ratio = figures["env_two_link"]["median"] / figures["reacher_v5"]["median"]
        print(f"  testbed env / Reacher-v5: {ratio:.2f}×")


if __name__ == "__main__":
    main()
