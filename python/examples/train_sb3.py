"""Train PPO (Stable-Baselines3) on testbed/ArmTracking-v0: a residual on
`pd` at a quarter of its gains, on the randomised paper scenario, with the
environment's defaults (50 Hz decisions over the 1 kHz plant, 4 s
episodes, the torque scale derived from the arm), on the Rust vector form
as an SB3 VecEnv (testbed.sb3); then report its return and constraint cost
on held-out seeds beside the zero residual (pd alone).

    pip install stable-baselines3          # or: bash python/setup-train-venv.sh
    python python/examples/train_sb3.py --out runs/ppo_arm                # 400 000 decisions, minutes
    python python/examples/train_sb3.py --timesteps 2048 --eval-seeds 1   # a smoke run
    python python/examples/train_sb3.py --smooth --out runs/ppo_smooth    # ramped, rate-penalised

`--smooth` trains the residual as a control engineer would deploy it: the
torque ramped across each decision rather than stepped (`smoothing="ramp"`),
the last action observed, and an action-rate term in the reward
(`action_rate_weight`, Isaac Lab's arm-reach task penalises the same);
`--smoothing`, `--action-rate-weight` and `--observe-action` set them one
by one, `--base-law` the law under the residual. The settings are saved
beside the model (`OUT.env.json`), where export_sb3_onnx.py reads them.

PPO's settings (HYPER) differ from SB3's defaults where those waste a
short budget: 2 048 decisions a rollout (8 arms x 256) rather than 16 384,
so 400 000 decisions are ~200 updates rather than 24; a discount of 0.98
(at 50 Hz it sees about 1 s, the time the error takes to settle); an
initial action noise of exp(-1) = 0.37 of the action's span rather than 1
(a residual of the whole span shakes the arm out of its envelope); the
learning rate falling linearly to 0; one torch thread (the network is
small; more threads only contend with the arms' stepping).
docs/results.md has what it learns and the commands that measure it.
"""

import argparse
import json
import time
from pathlib import Path

import gymnasium
import numpy as np

import testbed

#: The setting of the example: pd at K1 = K2 = 3.75 (a quarter of the
#: paper's), and a residual on it spanning 0.2 of the torque scale.
KWARGS = {"scenario": "paper_randomised", "base_law": "pd",
          "set": {"controller.k1": 3.75, "controller.k2": 3.75}}

#: `--smooth`'s action-rate weight: a full swing of the action (2) every
#: decision costs 4 × 0.05 = 0.2 a step, a fifth of an error at the envelope.
SMOOTH_RATE_WEIGHT = 0.05


def env_kwargs(a) -> dict:
    """KWARGS with the command line's smoothing and base law."""
    kw = dict(KWARGS, base_law=a.base_law)
    smoothing = "ramp" if a.smooth and a.smoothing is None else (a.smoothing or "hold")
    rate = SMOOTH_RATE_WEIGHT if a.smooth and a.action_rate_weight is None else (a.action_rate_weight or 0.0)
    if smoothing != "hold":
        kw["smoothing"] = smoothing
    if rate:
        kw["action_rate_weight"] = rate
    if a.observe_action or a.smooth:
        kw["observe_action"] = True
    return kw

#: PPO's settings (see above); everything else is SB3's default.
HYPER = {"n_steps": 256, "batch_size": 256, "gamma": 0.98,
         "learning_rate": lambda progress_remaining: 3e-4 * progress_remaining,
         "policy_kwargs": {"log_std_init": -1.0}}

#: Seeds the policy is judged on, far from those PPO draws in training.
HELD_OUT = 10_000


def evaluate(env, act, seeds):
    """Mean return and total cost steps over episodes of `seeds`."""
    returns, costs = [], 0.0
    for s in seeds:
        obs, _ = env.reset(seed=s)
        total, done = 0.0, False
        while not done:
            obs, r, term, trunc, info = env.step(act(obs))
            total, costs, done = total + r, costs + info["cost"], term or trunc
        returns.append(total)
    return float(np.mean(returns)), costs


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--timesteps", type=int, default=400_000, help="decisions to train on")
    p.add_argument("--n-envs", type=int, default=8)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--eval-seeds", type=int, default=20)
    p.add_argument("--out", default="runs/ppo_arm")
    p.add_argument("--base-law", default="pd", help="the law under the residual (default pd)")
    p.add_argument("--smooth", action="store_true",
                   help=f"ramp, observe the last action, action-rate weight {SMOOTH_RATE_WEIGHT}")
    p.add_argument("--smoothing", choices=["hold", "ramp", "low-pass"])
    p.add_argument("--action-rate-weight", type=float)
    p.add_argument("--observe-action", action="store_true")
    a = p.parse_args()
    kwargs = env_kwargs(a)
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecMonitor

    from testbed.sb3 import ArmTrackingSB3VecEnv, silent_logger

    torch.set_num_threads(1)
    venv = ArmTrackingSB3VecEnv(a.n_envs, **kwargs)
    venv.seed(a.seed)
    model = PPO("MlpPolicy", VecMonitor(venv), seed=a.seed, verbose=0, **HYPER)
    model.set_logger(silent_logger())
    start = time.perf_counter()
    model.learn(total_timesteps=a.timesteps)
    print(f"trained {a.timesteps} decisions in {time.perf_counter() - start:.0f} s")
    model.save(a.out)
    Path(a.out.removesuffix(".zip") + ".env.json").write_text(json.dumps(kwargs, indent=1) + "\n")
    env = gymnasium.make(testbed.ENV_ID, **kwargs)
    seeds = range(HELD_OUT, HELD_OUT + a.eval_seeds)
    zero = np.zeros(env.action_space.shape, np.float32)
    base = evaluate(env, lambda o: zero, seeds)
    ppo = evaluate(env, lambda o: model.predict(o, deterministic=True)[0], seeds)
    print(f"pd alone:   mean return {base[0]:.2f}, constraint cost {base[1]:.0f} steps")
    print(f"PPO on pd:  mean return {ppo[0]:.2f}, constraint cost {ppo[1]:.0f} steps")
    print(f"saved {a.out}.zip ({a.eval_seeds} held-out seeds from {HELD_OUT})")


if __name__ == "__main__":
    main()
