"""The vector form on several threads (the same bits as on one), and its
reset options (those of the single environment, per arm or for all)."""

import unittest

import numpy as np

import testbed
from helpers import assert_bits

#: Ten decisions an episode, the constraint from 20 ms on and a tight
#: breach factor, so that a short rollout has both kinds of end.
SHORT = dict(scenario="paper_randomised", episode_s=0.1, decimation=10,
             set={"controller.tc": 0.02}, breach_factor=1.5)


def rollout(num_threads, steps=30, num=6):
    env = testbed.ArmTrackingVecEnv(num, num_threads=num_threads, **SHORT)
    obs, _ = env.reset(seed=4)
    out = [obs]
    n = env.single_action_space.shape[0]
    for _ in range(steps):
        # A function of the observation, strong enough to breach now and then.
        actions = 0.5 * np.sin(3.0 * obs[:, :n] - 0.7 * obs[:, n:2 * n] + 0.3)
        obs, r, term, trunc, info = env.step(actions)
        out += [obs, r, term.astype(float), trunc.astype(float), info["cost"]]
    return env, out


class VectorThreads(unittest.TestCase):
    def test_threads_give_the_bits_of_one_thread(self):
        one_env, one = rollout(1)
        self.assertEqual(one_env.core.num_threads, 1)
        ends = np.array([x for i, x in enumerate(one[1:]) if i % 5 in (2, 3)])
        self.assertGreater(ends.sum(), 0, "the rollout has no end: it tests no autoreset")
        for threads in (2, 5, None):
            env, many = rollout(threads)
            if threads is not None:
                self.assertEqual(env.core.num_threads, threads)
            for k, (a, b) in enumerate(zip(one, many)):
                assert_bits(self, a, b, f"num_threads={threads}, item {k}")

    def test_a_bad_thread_count_is_refused_by_name(self):
        for bad, error in ((0, testbed.TestbedError), (-1, ValueError), (True, TypeError),
                           ("2", TypeError)):
            with self.assertRaisesRegex(error, "num_threads"):
                testbed.ArmTrackingVecEnv(2, num_threads=bad)

    def test_reset_options_are_the_single_envs(self):
        q = np.array([[0.1, 0.2], [0.3, 0.4], [0.5, 0.6]])
        qd = [0.05, -0.05]
        vec = testbed.ArmTrackingVecEnv(3, scenario="paper_randomised")
        for options in ({"initial_q": q, "initial_qd": qd}, {"initial_q": q.tolist()},
                        {"initial_qd": qd}):
            obs, _ = vec.reset(seed=9, options=options)
            for i in range(3):
                one = testbed.ArmTrackingEnv("paper_randomised")
                own = {k: (np.asarray(v)[i] if np.ndim(v) == 2 else v) for k, v in options.items()}
                o, _ = one.reset(seed=9 + i, options=own)
                assert_bits(self, obs[i], o, f"arm {i} with {sorted(options)}")
        # For that reset only: the next plain reset starts where the scenario says.
        plain, _ = vec.reset(seed=9)
        o, _ = testbed.ArmTrackingEnv("paper_randomised").reset(seed=9)
        assert_bits(self, plain[0], o, "a plain reset after options")
        with self.assertRaisesRegex(ValueError, "'x' is not taken"):
            vec.reset(options={"x": [1.0, 2.0]})
        with self.assertRaisesRegex(ValueError, "2 rows"):
            vec.reset(options={"initial_q": q[:2]})
        with self.assertRaisesRegex(TypeError, "dict"):
            vec.reset(options=[1])


if __name__ == "__main__":
    unittest.main()
