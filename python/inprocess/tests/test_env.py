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
            # And its rgb_array render, which the checker steps and draws.
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message=".*infinity.*")
                warnings.filterwarnings("ignore", message=".*alternative render modes.*")
                check_env(testbed.ArmTrackingEnv(render_mode="rgb_array", **kwargs),
                          skip_render_check=False)

    def test_spaces(self):
        env = gymnasium.make(ENV)
        self.assertEqual(env.observation_space.shape, (15,))
        self.assertEqual(env.action_space.shape, (2,))
        self.assertEqual(env.action_space.dtype, np.float32)
        self.assertEqual(len(testbed.observation_names(2)), 15)
        core = env.unwrapped.core
        # The rule: max(2 × gravity hold along the reference, 10 % of the
        # effort limit), at most the limit: 10 % of 500 N m here.
        self.assertTrue(np.array_equal(core.torque_scale, [50.0, 50.0]))
        # The defaults: 50 Hz decisions over the 1 kHz plant, 4 s episodes.
        self.assertEqual((core.decimation, core.dt, core.steps, core.decisions), (20, 0.02, 4000, 200))
        self.assertEqual(env.metadata["render_fps"], 50)


class SameBitsAsSim(unittest.TestCase):
    def test_zero_residual_on_the_scenarios_law_is_the_sim(self):
        for scenario, law in [("paper", "nac"), ("friction_noise", "nac"), ("ur5_randomised", "ctc")]:
            rows, _ = testbed.sim(scenario, duration=0.5, law=law)
            env = gymnasium.make(ENV, scenario=scenario, duration=0.5, base_law=law,
                                 decimation=1, scale_obs=False)
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
        env = gymnasium.make(ENV, scenario="paper_randomised", duration=0.2, base_law="nac",
                             decimation=1, scale_obs=False)
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
        env = gymnasium.make(ENV, duration=3.0, base_law="pd", set={"controller.tc": 1.0},
                             decimation=1, scale_obs=False)
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
        # A zero residual has no effort: the reward is the capped error term.
        want = -np.minimum((e / kc) ** 2, 100.0).mean(axis=1)
        self.assertTrue(np.allclose(out["reward"], want, rtol=0, atol=1e-12))

    def test_falling_arm_is_terminated_when_it_breaches(self):
        env = gymnasium.make(ENV, duration=5.0, set={"controller.tc": 0.1}, breach_factor=1.5)
        out, term, trunc = rollout(env, 0, lambda o: np.zeros(2))
        self.assertTrue(term and not trunc)
        core = env.unwrapped.core
        skipped = core.decisions - len(out["reward"])
        self.assertGreater(skipped, 0)
        # Ending early never pays: it is charged the worst reward of a step
        # (−100 − effort_weight) for every decision it skips.
        self.assertLessEqual(out["reward"][-1], -100.01 * skipped)
        env = gymnasium.make(ENV, duration=0.3, set={"controller.tc": 0.1}, breach_factor=None)
        out, term, trunc = rollout(env, 0, lambda o: np.zeros(2))
        self.assertTrue(trunc and not term)

    def test_step_after_the_end_and_bad_actions(self):
        env = gymnasium.make(ENV, duration=0.002, decimation=1)
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
        with self.assertRaisesRegex(testbed.TestbedError, r"torque_scale = \[1.0, 2.0, 3.0\]: has 3 values"):
            gymnasium.make(ENV, torque_scale=[1.0, 2.0, 3.0])
        with self.assertRaisesRegex(testbed.TestbedError, "breach_factor = 0.5: must be"):
            gymnasium.make(ENV, breach_factor=0.5)
        with self.assertRaisesRegex(testbed.TestbedError, "decimation = 0: must be"):
            gymnasium.make(ENV, decimation=0)
        with self.assertRaisesRegex(ValueError, "decimation = -3"):
            gymnasium.make(ENV, decimation=-3)
        with self.assertRaisesRegex(TypeError, "decimation: expected a whole number"):
            gymnasium.make(ENV, decimation=2.5)
        with self.assertRaisesRegex(TypeError, "decimation: expected a number, got bool"):
            gymnasium.make(ENV, decimation=True)
        with self.assertRaisesRegex(TypeError, "safe: expected True or False"):
            gymnasium.make(ENV, safe="yes")
        with self.assertRaisesRegex(testbed.TestbedError, "episode_s = 0: must be"):
            gymnasium.make(ENV, episode_s=0.0)
        with self.assertRaisesRegex(ValueError, "episode_s = 2 and duration = 3: give one"):
            gymnasium.make(ENV, episode_s=2.0, duration=3.0)
        # (gymnasium.make turns "human" into "rgb_array" under HumanRendering.)
        with self.assertRaisesRegex(ValueError, "render_mode = 'human'"):
            testbed.ArmTrackingEnv(render_mode="human")
        with self.assertRaisesRegex(ValueError, "option 'x' is not taken"):
            gymnasium.make(ENV).reset(options={"x": 1})
        with self.assertRaisesRegex(ValueError, "initial_q: 3 values"):
            gymnasium.make(ENV).reset(options={"initial_q": [0.0, 0.0, 0.0]})


class Vector(unittest.TestCase):
    def test_make_vec_steps_every_arm_as_its_own_env(self):
        venv = gymnasium.make_vec(ENV, num_envs=3, duration=0.01, base_law="pd", decimation=1)
        self.assertIsInstance(venv, testbed.ArmTrackingVecEnv)
        obs, _ = venv.reset(seed=40)
        self.assertEqual(obs.shape, (3, 15))
        actions = np.tile([0.01, -0.02], (3, 1))
        singles = [gymnasium.make(ENV, duration=0.01, base_law="pd", decimation=1) for _ in range(3)]
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


    def test_a_fortran_ordered_action_reaches_its_own_arm(self):
        # Regression (#48 N1): the core read memory order, so arm 0's
        # action went to arm 1 when the array was column after column.
        a = np.array([[1.0, -1.0], [-0.5, 0.25]])
        c_core, f_core = testbed.VecEnvCore(2, duration=0.1), testbed.VecEnvCore(2, duration=0.1)
        c_core.reset(3)
        f_core.reset(3)
        want = c_core.step(a)[0]
        got = f_core.step(np.asfortranarray(a))[0]
        assert_bits(self, got, want, "observations after a Fortran-ordered step")
        # The wrapper's transposed product, (W @ obs.T).T, is Fortran-ordered too.
        venv = gymnasium.make_vec(ENV, num_envs=2, duration=0.1)
        obs, _ = venv.reset(seed=3)
        w = np.ones((2, obs.shape[1])) * 0.01
        act = (w @ obs.T).T
        self.assertTrue(act.flags.f_contiguous and not act.flags.c_contiguous)
        venv.step(act)


class RlReady(unittest.TestCase):
    def test_render_rgb_array_draws_the_arm_for_record_video(self):
        env = gymnasium.make(ENV, render_mode="rgb_array")
        env.reset(seed=0)
        frame = env.render()
        self.assertEqual((frame.shape, frame.dtype), ((480, 480, 3), np.uint8))
        self.assertTrue((frame == [40, 40, 40]).all(axis=2).sum() > 100, "the arm is drawn")
        self.assertTrue((frame == [150, 190, 240]).all(axis=2).any(), "and its reference")
        for _ in range(5):
            env.step(np.ones(2, np.float32))
        self.assertFalse(np.array_equal(frame, env.render()), "it moves")
        self.assertIsNone(gymnasium.make(ENV).unwrapped.render())
        # SB3's make_vec_env passes render_mode="rgb_array" to every env.
        venv = gymnasium.make_vec(ENV, num_envs=2, render_mode="rgb_array")
        venv.reset(seed=0)
        frames = venv.render()
        self.assertEqual(len(frames), 2)
        self.assertEqual(frames[1].shape, (480, 480, 3))

    def test_record_video_takes_the_frames(self):
        from gymnasium.wrappers import RenderCollection
        env = RenderCollection(gymnasium.make(ENV, render_mode="rgb_array", duration=0.1))
        env.reset(seed=0)
        for _ in range(3):
            env.step(np.zeros(2, np.float32))
        self.assertEqual(len(env.render()), 4)

    def test_decimation_holds_the_action_and_keeps_the_sims_bits(self):
        rows, _ = testbed.sim("paper", duration=0.5, law="pd")
        env = gymnasium.make(ENV, duration=0.5, base_law="pd", decimation=20)
        out, term, trunc = rollout(env, env.unwrapped.core.seed, lambda o: np.zeros(2))
        self.assertTrue(trunc and not term)
        self.assertEqual(len(out["reward"]), 25)
        assert_bits(self, out["q"][:-1], rows["q"][20::20], "q at each decision")

    def test_the_observation_is_scaled(self):
        env = gymnasium.make(ENV, base_law="pd")
        obs, _ = env.reset(seed=0)
        raw = gymnasium.make(ENV, base_law="pd", scale_obs=False)
        raw_obs, _ = raw.reset(seed=0)
        v = env.unwrapped.core.velocity_scale
        assert_bits(self, obs[0:2], raw_obs[0:2] / raw_obs[12:14], "e / k_c")
        assert_bits(self, obs[2:4], raw_obs[2:4] / v, "ė / v")
        assert_bits(self, obs[4:6], raw_obs[4:6], "q")

    def test_safe_mode_reports_cost_and_never_ends_early(self):
        kwargs = {"duration": 1.0, "set": {"controller.tc": 0.1}, "torque_scale": [200.0, 200.0]}
        env = gymnasium.make(ENV, safe=True, **kwargs)
        out, term, trunc = rollout(env, 0, lambda o: np.ones(2))
        self.assertTrue(trunc and not term)
        self.assertEqual(len(out["reward"]), env.unwrapped.core.decisions)
        self.assertGreater(out["cost"].sum(), 0)
        self.assertTrue(np.all(out["reward"] >= -100.01), "the reward is not charged for the cost")
        plain = gymnasium.make(ENV, **kwargs)
        _, term, _ = rollout(plain, 0, lambda o: np.ones(2))
        self.assertTrue(term, "outside safe mode the same breach ends the episode")

    def test_smoothing_observing_the_action_and_its_rate_in_the_reward(self):
        """#59 item 1: a ramp or a low-pass in place of the held action,
        the last action at the observation's end, an action-rate term."""
        kw = {"duration": 0.5, "base_law": "pd"}
        held = gymnasium.make(ENV, **kw)
        for smoothing in ["ramp", "low-pass"]:
            env = gymnasium.make(ENV, smoothing=smoothing, observe_action=True, **kw)
            core = env.unwrapped.core
            self.assertEqual((core.smoothing, core.observe_action), (smoothing, True))
            self.assertEqual(core.smoothing_tau_s, 0.02 if smoothing == "low-pass" else None)
            self.assertEqual(env.observation_space.shape, (17,))
            self.assertEqual(testbed.observation_names(2, True)[-2:], ["a0", "a1"])
            obs, _ = env.reset(seed=0)
            self.assertTrue(np.array_equal(obs[15:], [0.0, 0.0]))
            held.reset(seed=0)
            a = np.array([0.5, -2.0], np.float32)
            obs, *_ = env.step(a)
            # The clipped action, as the policy gave it.
            self.assertTrue(np.array_equal(obs[15:], [0.5, -1.0]))
            held.step(a)
            # The shaping itself is pinned in Rust (gym-env's smoothing
            # tests, policy/tests/smoothing.rs); here: it acts.
            self.assertFalse(np.array_equal(env.unwrapped.core.true_state[0],
                                            held.unwrapped.core.true_state[0]))
        # The rate term: a constant action pays it once, from rest.
        base = gymnasium.make(ENV, **kw)
        rated = gymnasium.make(ENV, action_rate_weight=1.0, **kw)
        for e in (base, rated):
            e.reset(seed=0)
        ones = np.ones(2, np.float32)
        r0, r1 = base.step(ones)[1], rated.step(ones)[1]
        self.assertAlmostEqual(r0 - r1, 1.0, places=12)
        r0, r1 = base.step(ones)[1], rated.step(ones)[1]
        self.assertEqual(r0, r1)
        for bad, what in [({"smoothing": "spline"}, "smoothing = spline: must be one of"),
                          ({"smoothing": "low-pass", "smoothing_tau_s": 0.0}, "smoothing_tau_s = 0: must be"),
                          ({"action_rate_weight": -1.0}, "action_rate_weight = -1: must be")]:
            with self.assertRaisesRegex(testbed.TestbedError, what):
                gymnasium.make(ENV, **bad)
        with self.assertRaisesRegex(TypeError, "observe_action: expected True or False"):
            gymnasium.make(ENV, observe_action=1)
        with self.assertRaisesRegex(ValueError, "smoothing_tau_s = 0.05: only smoothing=\"low-pass\""):
            gymnasium.make(ENV, smoothing="ramp", smoothing_tau_s=0.05)
        # What the core says is what it takes back.
        core = gymnasium.make(ENV, smoothing="ramp").unwrapped.core
        gymnasium.make(ENV, smoothing=core.smoothing, smoothing_tau_s=core.smoothing_tau_s)

    def test_reset_options_set_the_start(self):
        env = gymnasium.make(ENV)
        env.reset(seed=0, options={"initial_q": [0.3, -0.2], "initial_qd": [0.0, 0.1]})
        q, qd = env.unwrapped.core.true_state
        self.assertTrue(np.array_equal(q, [0.3, -0.2]) and np.array_equal(qd, [0.0, 0.1]))


class ModuleQualifiedId(unittest.TestCase):
    def test_a_process_that_never_imported_testbed_makes_the_env_by_module_id(self):
        import subprocess
        import sys

        code = ("import gymnasium, sys\n"
                "env = gymnasium.make('testbed:testbed/ArmTracking-v0', duration=0.05)\n"
                "env.reset(seed=0)\n"
                "assert 'testbed' in sys.modules\n"
                "print('ok')\n")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("ok", out.stdout)

if __name__ == "__main__":
    unittest.main()
