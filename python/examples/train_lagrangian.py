"""Cost-aware training: PPO-Lagrangian (Ray, Achiam & Amodei 2019,
"Benchmarking Safe Exploration in Deep Reinforcement Learning") on the
environment's safe-RL mode, where reward and cost are separate signals.

The setting lets them pull apart: a residual on `pd` at a sixteenth of its
gains (K1 = K2 = 0.9375), which on its own leaves the envelope after T_c
on about a third of its decisions, and an effort weight of 0.5 that makes
the residual dear: a residual that saves effort by letting the error grow
past the envelope gains reward and pays in cost. The learner
maximises reward − λ · cost; after every rollout λ follows the constraint
by dual ascent, λ ← max(0, λ + lr_λ · (cost rate − budget)), where the
cost rate is the rollout's mean `info["cost"]` per decision.

    python python/examples/train_lagrangian.py --timesteps 100000
    python python/examples/train_lagrangian.py --timesteps 4096 --eval-seeds 1   # a smoke run

It prints λ and the cost rate after every rollout, then the mean return
and cost steps on held-out seeds of pd alone and of the learnt residual.
Needs stable-baselines3 (python/setup-train-venv.sh makes an environment).
"""

import argparse
import sys
from pathlib import Path

import gymnasium
import numpy as np

import testbed

sys.path.insert(0, str(Path(__file__).parent))
from train_sb3 import evaluate  # noqa: E402  (one episode per seed: mean return, cost steps)

#: Safe mode (no early end; the reward never counts the cost), a weak
#: base law and a dear effort term.
KWARGS = {"scenario": "paper_randomised", "base_law": "pd", "safe": True, "effort_weight": 0.5,
          "set": {"controller.k1": 0.9375, "controller.k2": 0.9375}}

#: Seeds the policy is judged on, far from those drawn in training.
HELD_OUT = 10_000


def make_penalty_wrapper(VecEnvWrapper):
    """The wrapper class (SB3 imported by the caller)."""

    class LagrangianPenalty(VecEnvWrapper):
        """Gives the learner reward − λ · cost; keeps every step's cost."""

        def __init__(self, venv, lam: float):
            super().__init__(venv)
            self.lam = lam
            self.costs = []

        def reset(self):
            return self.venv.reset()

        def step_wait(self):
            obs, rewards, dones, infos = self.venv.step_wait()
            cost = np.array([info["cost"] for info in infos])
            self.costs.append(cost)
            return obs, rewards - self.lam * cost, dones, infos

    return LagrangianPenalty


def make_dual_ascent(BaseCallback):
    """The callback class that moves λ after each rollout."""

    class DualAscent(BaseCallback):
        def __init__(self, penalty, budget: float, lr: float):
            super().__init__()
            self.penalty, self.budget, self.lr = penalty, budget, lr
            self.history = []

        def _on_step(self) -> bool:
            return True

        def _on_rollout_end(self) -> None:
            rate = float(np.mean(self.penalty.costs)) if self.penalty.costs else 0.0
            self.penalty.costs.clear()
            self.penalty.lam = max(0.0, self.penalty.lam + self.lr * (rate - self.budget))
            self.history.append((rate, self.penalty.lam))
            self.logger.record("lagrangian/cost_rate", rate)
            self.logger.record("lagrangian/lambda", self.penalty.lam)
            print(f"rollout {len(self.history):3d}: cost rate {rate:.4f}, lambda {self.penalty.lam:.3f}",
                  flush=True)

    return DualAscent


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--timesteps", type=int, default=100_000, help="decisions to train on")
    p.add_argument("--n-envs", type=int, default=16)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--budget", type=float, default=0.0,
                   help="the cost rate allowed per decision (0: the constraint always)")
    p.add_argument("--lambda-lr", type=float, default=5.0, help="the dual step lr_λ")
    p.add_argument("--eval-seeds", type=int, default=10)
    p.add_argument("--out", default="runs/ppo_lagrangian")
    a = p.parse_args()
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import VecEnvWrapper, VecMonitor

    from testbed.sb3 import ArmTrackingSB3VecEnv, silent_logger

    venv = ArmTrackingSB3VecEnv(a.n_envs, **KWARGS)
    venv.seed(a.seed)
    penalty = make_penalty_wrapper(VecEnvWrapper)(VecMonitor(venv), lam=0.0)
    dual = make_dual_ascent(BaseCallback)(penalty, a.budget, a.lambda_lr)
    model = PPO("MlpPolicy", penalty, seed=a.seed, n_steps=256, batch_size=512, verbose=0)
    model.set_logger(silent_logger())
    model.learn(total_timesteps=a.timesteps, callback=dual)
    model.save(a.out)
    seeds = range(HELD_OUT, HELD_OUT + a.eval_seeds)
    zero = np.zeros(venv.action_space.shape, np.float32)
    env = gymnasium.make(testbed.ENV_ID, **KWARGS)
    base = evaluate(env, lambda o: zero, seeds)
    ppo = evaluate(env, lambda o: model.predict(o, deterministic=True)[0], seeds)
    print(f"pd alone:          mean return {base[0]:.2f}, constraint cost {base[1]:.0f} steps")
    print(f"PPO-Lagrangian:    mean return {ppo[0]:.2f}, constraint cost {ppo[1]:.0f} steps")
    print(f"final lambda {penalty.lam:.3f}; saved {a.out}.zip ({a.eval_seeds} held-out seeds from {HELD_OUT})")


if __name__ == "__main__":
    main()
