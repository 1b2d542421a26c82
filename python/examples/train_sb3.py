"""Train PPO (Stable-Baselines3) on testbed/ArmTracking-v0 (8 environments
in SB3's own vector wrapper), and report its return and constraint cost.

    pip install stable-baselines3          # or: pip install -e 'python/inprocess[train]'
    python python/examples/train_sb3.py --timesteps 200000 --out runs/ppo_arm

Not needed by the tests (and not run by them: SB3 brings PyTorch). The
policy is a residual on `pd`.
"""

import argparse

import gymnasium
import numpy as np

import testbed


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scenario", default="paper")
    p.add_argument("--duration", type=float, default=2.0)
    p.add_argument("--timesteps", type=int, default=200_000)
    p.add_argument("--out", default="runs/ppo_arm")
    a = p.parse_args()
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env

    kwargs = {"scenario": a.scenario, "duration": a.duration, "base_law": "pd"}
    venv = make_vec_env(testbed.ENV_ID, n_envs=8, env_kwargs=kwargs)
    model = PPO("MlpPolicy", venv, verbose=1)
    model.learn(total_timesteps=a.timesteps)
    model.save(a.out)
    env = gymnasium.make(testbed.ENV_ID, **kwargs)
    obs, _ = env.reset(seed=0)
    total, cost, done = 0.0, 0.0, False
    while not done:
        action, _ = model.predict(obs, deterministic=True)
        obs, r, term, trunc, info = env.step(np.asarray(action))
        total, cost, done = total + r, cost + info["cost"], term or trunc
    print(f"return {total:.2f}, constraint cost {cost:.0f} steps; saved {a.out}.zip")


if __name__ == "__main__":
    main()
