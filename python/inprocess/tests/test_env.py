"""The Gymnasium environment: Gymnasium's own checker, the sim's bits with
a zero residual, seeds, the vector form, and bad input."""

import unittest
import warnings

import gymnasium
import numpy as np
from gymnasium.utils.env_checker import check_env

import testbed
from helpers import ROOT, assert_bits

ENV = testbed.ENV_ID


def rollout(env, seed, action_fn, steps=None):
    obs, _ = env.reset(seed=seed)
    out = {"obs": [obs], "reward": [], "cost": [], "q": []}
    done, k = False, 0
    while not done and (steps is None or k < steps):
        obs, r, term, trunc, info = env.step(action_fn(obs))
        out["obs"].append(obs)
        out["reward"].append(r)
        out["cost"].append(info["cost"])
        out["q"].append(env.unwrapped.core.true_state[0])
        done, k = term or trunc, k + 1
    return {k: np.array(v) for k, v in out.items()}, term, trunc


class Checker(unittest.TestCase):
    def test_gymnasium_env_checker_passes(self):
        for kwargs in [{}, {"base_law": "pd"}, {"robot": str(ROOT / "robots/iiwa14.urdf")}]:
            with warnings.catch_warnings():
                # Unbounded observations are what they are (MuJoCo's are too).
                warnings.filterwarnings("ignore", message=".*infinity.*")
                check_env(gymnasium.make(ENV, **kwargs).unwrapped, skip_render_check=True)

    def test_spaces(self):
        env = gymnasium.make(ENV)
        self.assertEqual(env.observation_space.shape, (15,))
        self.assertEqual(env.action_space.shape, (2,))
        self.assertEqual(env.action_space.dtype, np.float32)
        self.assertEqual(len(testbed.observation_names(2)), 15)
        self.assertTrue(np.array_equal(env.unwrapped.core.torque_scale, [500.0, 500.0]))


class SameBitsAsSim(unittest.TestCase):
    def test_zero_residual_on_the_scenarios_law_is_the_sim(self):
        for scenario, law in [("paper", "nac"), ("friction_noise", "nac"), ("ur5_randomised", "ctc")]:
            rows, _ = testbed.sim(scenario, duration=0.5, law=law)
            env = gymnasium.make(ENV, scenario=scenario, duration=0.5, base_law=law)
            seed = env.unwrapped.core.seed  # the scenario's own seed
            n = rows["q"].shape[1]
            out, term, trunc = rollout(env, seed, lambda o: np.zeros(n))
            self.assertTrue(trunc and not term)
            # Row k is the state before step k; the env's k-th q is after it.
            assert_bits(self, out["q"][:-1], rows["q"][1:], f"{scenario} q")
            obs = out["obs"][:-1]
            assert_bits(self, obs[:, 2 * n:3 * n], rows["q_measured"], f"{scenario} measured q")
            assert_bits(self, obs[:, 4 * n:5 * n], rows["q_d"], f"{scenario} q_d")
            assert_bits(self, obs[:, :n], rows["z1"], f"{scenario} e")

    def test_a_seed_draws_the_scenarios_randomise_table(self):
        env = gymnasium.make(ENV, scenario="paper_randomised", duration=0.2, base_law="nac")
        for seed in (0, 5):
            rows, _ = testbed.sim("paper_randomised", duration=0.2, set={"seed": seed})
            out, _, _ = rollout(env, seed, lambda o: np.zeros(2))
            assert_bits(self, out["q"][:-1], rows["q"][1:], f"seed {seed}")
        a, _, _ = rollout(env, 11, lambda o: np.zeros(2))
        b, _, _ = rollout(env, 12, lambda o: np.zeros(2))
        self.assertFalse(np.array_equal(a["obs"][0], b["obs"][0]), "seeds draw different starts")
        c, _, _ = rollout(env, 11, lambda o: np.zeros(2))
        assert_bits(self, a["obs"], c["obs"], "the same seed, the same episode")


class Contract(unittest.TestCase):
    def test_reward_cost_and_end(self):
        env = gymnasium.make(ENV, duration=3.0, base_law="pd", set={"controller.tc": 1.0})
        out, term, trunc = rollout(env, 0, lambda o: np.zeros(2))
        t = np.arange(1, len(out["cost"]) + 1) * 1e-3
        self.assertTrue(trunc and not term)
        self.assertEqual(len(out["cost"]), 3000)
        self.assertTrue(np.all(out["cost"][t < 1.0] == 0.0), "no cost before T_c")
        # Recomputed from the observation: e and k_c (true q has no noise here).
        obs = out["obs"][1:]
        e, kc = obs[:, 0:2], obs[:, 12:14]
        outside = (np.abs(e) >= kc).any(axis=1) & (t >= 1.0)
        self.assertTrue(np.array_equal(out["cost"], outside.astype(float)))
        tau_scale = 500.0
        self.assertTrue(np.all(out["reward"] <= -((e / kc) ** 2).mean(axis=1) + 1e-12))
        del tau_scale

    def test_falling_arm_is_terminated_when_it_breaches(self):
        env = gymnasium.make(ENV, duration=5.0, set={"controller.tc": 0.1}, breach_factor=1.5)
        out, term, trunc = rollout(env, 0, lambda o: np.zeros(2))
        self.assertTrue(term and not trunc)
        self.assertLess(len(out["reward"]), 5000)
        env = gymnasium.make(ENV, duration=0.3, set={"controller.tc": 0.1}, breach_factor=None)
        out, term, trunc = rollout(env, 0, lambda o: np.zeros(2))
        self.assertTrue(trunc and not term)

    def test_step_after_the_end_and_bad_actions(self):
        env = gymnasium.make(ENV, duration=0.002)
        with self.assertRaises(gymnasium.error.ResetNeeded):
            env.step(np.zeros(2))
        env.reset(seed=0)
        with self.assertRaisesRegex(ValueError, "action: 3 values; this arm needs 2"):
            env.step(np.zeros(3))
        with self.assertRaisesRegex(ValueError, r"action\[1\] = NaN is not a finite number"):
            env.step(np.array([0.0, np.nan]))
        with self.assertRaisesRegex(TypeError, "action: expected 2 numbers"):
            env.step(np.array(["a", "b"]))
        with self.assertRaisesRegex(TypeError, "action: expected 2 numbers"):
            env.step(np.zeros((2, 1)))
        env.step(np.zeros(2, dtype=np.float32))
        _, _, _, trunc, _ = env.step([0.5, -0.5])
        self.assertTrue(trunc)
        with self.assertRaisesRegex(RuntimeError, "call reset"):
            env.unwrapped.step(np.zeros(2))

    def test_bad_arguments(self):
        with self.assertRaisesRegex(TypeError, "unexpected keyword argument 'colour'"):
            gymnasium.make(ENV, colour="red")
        with self.assertRaisesRegex(ValueError, "base_law: unknown law 'pid'"):
            gymnasium.make(ENV, base_law="pid")
        with self.assertRaisesRegex(testbed.TestbedError, "torque_scale: 3 values"):
            gymnasium.make(ENV, torque_scale=[1.0, 2.0, 3.0])
        with self.assertRaisesRegex(testbed.TestbedError, "breach_factor = 0.5"):
            gymnasium.make(ENV, breach_factor=0.5)
        with self.assertRaisesRegex(ValueError, "options"):
            gymnasium.make(ENV).reset(options={"x": 1})


class Vector(unittest.TestCase):
    def test_make_vec_steps_every_arm_as_its_own_env(self):
        venv = gymnasium.make_vec(ENV, num_envs=3, duration=0.01, base_law="pd")
        self.assertIsInstance(venv, testbed.ArmTrackingVecEnv)
        obs, _ = venv.reset(seed=40)
        self.assertEqual(obs.shape, (3, 15))
        actions = np.tile([0.01, -0.02], (3, 1))
        singles = [gymnasium.make(ENV, duration=0.01, base_law="pd") for _ in range(3)]
        single_obs = [e.reset(seed=40 + i)[0] for i, e in enumerate(singles)]
        assert_bits(self, obs, np.stack(single_obs), "reset")
        for k in range(10):
            obs, rew, term, trunc, info = venv.step(actions)
            outs = [e.step(actions[i]) for i, e in enumerate(singles)]
            assert_bits(self, obs, np.stack([o[0] for o in outs]), f"obs at {k}")
            assert_bits(self, rew, [o[1] for o in outs], f"reward at {k}")
            self.assertTrue(np.array_equal(info["cost"], [o[4]["cost"] for o in outs]))
        self.assertTrue(trunc.all())
        # Next-step autoreset: the ended arms start again, reward 0.
        obs, rew, term, trunc, _ = venv.step(actions)
        self.assertTrue(np.all(rew == 0.0) and not trunc.any() and not term.any())
        self.assertTrue(np.all(obs[:, -1] == 0.0))

    def test_bad_actions(self):
        venv = gymnasium.make_vec(ENV, num_envs=2)
        venv.reset(seed=0)
        with self.assertRaisesRegex(ValueError, r"shape \[2, 3\]"):
            venv.step(np.zeros((2, 3)))
        a = np.zeros((2, 2))
        a[1, 0] = np.inf
        with self.assertRaisesRegex(ValueError, r"actions\[1, 0\] = inf"):
            venv.step(a)


if __name__ == "__main__":
    unittest.main()
