"""Train PPO (Stable-Baselines3) on testbed/ArmTracking-v0: a residual on
`pd` at a quarter of its gains, on the randomised paper scenario, with the
environment's defaults (50 Hz decisions over the 1 kHz plant, 4 s
episodes, the torque scale derived from the arm); then report its return
and constraint cost on held-out seeds beside the zero residual (pd alone).

    pip install stable-baselines3          # or: pip install -e 'python/inprocess[train]'
    python python/examples/train_sb3.py --timesteps 150000 --out runs/ppo_arm
    python python/examples/train_sb3.py --timesteps 2000 --eval-seeds 1   # a smoke run

SB3's make_vec_env passes render_mode="rgb_array" to every environment;
the environment draws the arm for it (and for Gymnasium's RecordVideo).
"""

import argparse

import gymnasium
import numpy as np

import testbed

#: The setting of the example: pd at K1 = K2 = 3.75 (a quarter of the
#: paper's), and a residual on it spanning 0.2 of the torque scale.
KWARGS = {"scenario": "paper_randomised", "base_law": "pd",
          "set": {"controller.k1": 3.75, "controller.k2": 3.75}}

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
    p.add_argument("--timesteps", type=int, default=150_000, help="decisions to train on")
    p.add_argument("--n-envs", type=int, default=8)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--eval-seeds", type=int, default=20)
    p.add_argument("--out", default="runs/ppo_arm")
    a = p.parse_args()
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env

    venv = make_vec_env(testbed.ENV_ID, n_envs=a.n_envs, seed=a.seed, env_kwargs=KWARGS)
    model = PPO("MlpPolicy", venv, seed=a.seed, verbose=0)
    model.learn(total_timesteps=a.timesteps)
    model.save(a.out)
    env = gymnasium.make(testbed.ENV_ID, **KWARGS)
    seeds = range(HELD_OUT, HELD_OUT + a.eval_seeds)
    zero = np.zeros(env.action_space.shape, np.float32)
    base = evaluate(env, lambda o: zero, seeds)
    ppo = evaluate(env, lambda o: model.predict(o, deterministic=True)[0], seeds)
    print(f"pd alone:   mean return {base[0]:.2f}, constraint cost {base[1]:.0f} steps")
    print(f"PPO on pd:  mean return {ppo[0]:.2f}, constraint cost {ppo[1]:.0f} steps")
    print(f"saved {a.out}.zip ({a.eval_seeds} held-out seeds from {HELD_OUT})")


if __name__ == "__main__":
    main()
