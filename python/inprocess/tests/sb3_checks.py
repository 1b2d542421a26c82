"""The Stable-Baselines3 adapter, run in an environment with SB3 and torch
(test_sb3.py starts it there: TESTBED_SB3_PYTHON, or the one
python/setup-train-venv.sh makes). Not named test_*: the module's own
environment has no SB3, so discovery there must not import it.

    TESTBED_SB3_PYTHON -m unittest -v sb3_checks     (from this folder)
"""

import sys
import tempfile
import types
import unittest
import warnings
from pathlib import Path

import gymnasium
import numpy as np
from stable_baselines3 import PPO
from stable_baselines3.common.env_checker import check_env
from stable_baselines3.common.vec_env import VecCheckNan, VecMonitor, VecVideoRecorder

import testbed
from testbed.sb3 import ArmTrackingSB3VecEnv, silent_logger

#: Ten decisions an episode, the constraint from 20 ms on and a tight
#: breach factor: a short rollout has both kinds of end.
SHORT = dict(scenario="paper_randomised", episode_s=0.1, decimation=10,
             set={"controller.tc": 0.02}, breach_factor=1.5)


def policy(obs, n):
    """A function of the observation alone, strong enough to breach now and then."""
    return 0.5 * np.sin(3.0 * obs[:, :n] - 0.7 * obs[:, n:2 * n] + 0.3)


def bits(a):
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64).tolist()


class SB3Adapter(unittest.TestCase):
    def test_sb3_check_env_passes_the_single_env(self):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            check_env(gymnasium.make(testbed.ENV_ID).unwrapped, warn=True)
        # Only the warnings it gives every unbounded observation (as MuJoCo's).
        for w in caught:
            self.assertRegex(str(w.message), "(?i)unbounded|symmetric|normaliz|inf|dtype|float64",
                             str(w.message))

    def test_the_vec_env_speaks_sb3s_protocol(self):
        num = 5
        venv = VecCheckNan(ArmTrackingSB3VecEnv(num, num_threads=2, **SHORT), raise_exception=True)
        venv.seed(3)
        obs = venv.reset()
        self.assertEqual(obs.shape, (num,) + venv.observation_space.shape)
        self.assertEqual(venv.unwrapped.reset_infos[2]["seed"], 5)
        self.assertTrue(all(venv.observation_space.contains(o) for o in obs))
        n = venv.action_space.shape[0]
        ended = {"terminated": 0, "truncated": 0}
        for _ in range(30):
            obs, rewards, dones, infos = venv.step(policy(obs, n).astype(np.float32))
            self.assertEqual(obs.shape, (num,) + venv.observation_space.shape)
            self.assertEqual((rewards.shape, rewards.dtype), ((num,), np.float32))
            self.assertEqual((dones.shape, dones.dtype), ((num,), np.bool_))
            self.assertEqual(len(infos), num)
            for d, info in zip(dones, infos):
                self.assertIn(info["cost"], (0.0, 1.0))
                self.assertEqual("terminal_observation" in info, bool(d))
                if d:
                    self.assertTrue(venv.observation_space.contains(info["terminal_observation"]))
                    ended["truncated" if info["TimeLimit.truncated"] else "terminated"] += 1
        self.assertGreater(ended["terminated"], 0, "no breach: the check saw one kind of end")
        self.assertGreater(ended["truncated"], 0, "no time limit: the check saw one kind of end")

    def test_seeding_repeats_and_seeds_differ(self):
        def run(seed):
            venv = ArmTrackingSB3VecEnv(3, **SHORT)
            venv.seed(seed)
            out = [venv.reset()]
            for _ in range(12):
                out.append(venv.step(policy(out[-1], 2))[0])
            return np.array(out)

        self.assertEqual(bits(run(7)), bits(run(7)))
        self.assertNotEqual(bits(run(7)), bits(run(8)))

    def test_a_rollout_is_the_gymnasium_vector_forms_without_its_reset_steps(self):
        num, steps = 4, 40
        gym = testbed.ArmTrackingVecEnv(num, **SHORT)
        obs, _ = gym.reset(seed=21)
        n = gym.single_action_space.shape[0]
        # Gymnasium's NEXT_STEP: arm i's transitions, the reset steps folded
        # in (their observation is the next episode's first).
        expected = [[] for _ in range(num)]
        was_done = np.zeros(num, dtype=bool)
        for _ in range(steps):
            obs, r, term, trunc, info = gym.step(policy(obs, n))
            for i in range(num):
                if was_done[i]:
                    last = expected[i][-1]
                    last["terminal"], last["obs"] = last["obs"], bits(obs[i])
                else:
                    expected[i].append({"obs": bits(obs[i]), "reward": r[i], "done": term[i] or trunc[i],
                                        "cost": info["cost"][i], "terminal": None})
            was_done = term | trunc
        sb3 = ArmTrackingSB3VecEnv(num, **SHORT)
        sb3.seed(21)
        obs = sb3.reset()
        got = [[] for _ in range(num)]
        for _ in range(steps):
            obs, r, dones, infos = sb3.step(policy(obs, n))
            for i in range(num):
                t = infos[i].get("terminal_observation")
                got[i].append({"obs": bits(obs[i]), "reward": np.float32(r[i]), "done": dones[i],
                               "cost": infos[i]["cost"], "terminal": None if t is None else bits(t)})
        checked_ends = 0
        for i in range(num):
            # Gymnasium's last transition may be an end whose reset step is past the rollout.
            want = expected[i][:-1] if was_done[i] else expected[i]
            self.assertGreater(len(want), 0)
            for k, w in enumerate(want):
                g = got[i][k]
                self.assertEqual(g["obs"], w["obs"], f"arm {i}, transition {k}: observation")
                self.assertEqual(g["reward"], np.float32(w["reward"]), f"arm {i}, transition {k}")
                self.assertEqual((g["done"], g["cost"]), (w["done"], w["cost"]), f"arm {i}, transition {k}")
                self.assertEqual(g["terminal"], w["terminal"], f"arm {i}, transition {k}: terminal")
                checked_ends += w["terminal"] is not None
        self.assertGreater(checked_ends, 0, "no episode ended: nothing checked the autoreset")

    def test_ppo_learns_on_it(self):
        venv = VecMonitor(ArmTrackingSB3VecEnv(8, scenario="paper", episode_s=0.2, base_law="pd"))
        model = PPO("MlpPolicy", venv, n_steps=32, batch_size=64, n_epochs=2, seed=0, device="cpu",
                    verbose=0)
        model.set_logger(silent_logger())
        leftovers = set(Path(tempfile.gettempdir()).glob("SB3-*"))
        model.learn(total_timesteps=512)
        # SB3's own logger would have left an empty /tmp/SB3-<date>/.
        self.assertEqual(set(Path(tempfile.gettempdir()).glob("SB3-*")), leftovers)
        self.assertGreaterEqual(model.num_timesteps, 512)
        # Episodes ended (ten decisions each) and VecMonitor counted them.
        self.assertGreater(len(model.ep_info_buffer), 0)
        self.assertTrue(all(np.isfinite(e["r"]) for e in model.ep_info_buffer))
        action, _ = model.predict(venv.reset(), deterministic=True)
        self.assertEqual(action.shape, (8, 2))
        self.assertTrue(np.all(np.abs(action) <= 1.0))

    def test_attributes_methods_and_options(self):
        venv = ArmTrackingSB3VecEnv(3, render_mode="rgb_array")
        self.assertEqual(venv.get_attr("render_mode"), ["rgb_array"] * 3)
        self.assertEqual(venv.get_attr("observation_space", indices=[1])[0], venv.observation_space)
        venv.set_attr("note", 7, indices=[0, 2])
        self.assertEqual(venv.get_attr("note", indices=[0, 2]), [7, 7])
        with self.assertRaises(AttributeError):
            venv.get_attr("note", indices=1)
        self.assertEqual(venv.env_is_wrapped(gymnasium.Wrapper), [False] * 3)
        venv.seed(30)
        venv.reset()
        self.assertEqual(venv.get_attr("seed"), [30, 31, 32])
        pictures = venv.env_method("render", indices=[1])
        self.assertEqual(pictures[0].shape, (480, 480, 3))
        # set_options: the Gymnasium vector form's reset options.
        q = [[0.1, 0.2], [0.3, 0.4], [0.5, 0.6]]
        venv.seed(2)
        venv.set_options([{"initial_q": row} for row in q])
        obs = venv.reset()
        want, _ = testbed.ArmTrackingVecEnv(3).reset(seed=2, options={"initial_q": q})
        self.assertEqual(bits(obs), bits(want))

    def test_vec_video_recorder_captures_the_arms(self):
        venv = ArmTrackingSB3VecEnv(4, episode_s=0.2, render_mode="rgb_array")
        self.assertEqual(venv.metadata["render_fps"], 50)
        tiled = venv.render()
        self.assertEqual(tiled.shape, (960, 960, 3))
        # The recorder needs MoviePy only to write the file: a stand-in
        # lets it capture frames without encoding them.
        sys.modules.setdefault("moviepy", types.ModuleType("moviepy"))
        with tempfile.TemporaryDirectory() as folder:
            rec = VecVideoRecorder(venv, folder, record_video_trigger=lambda step: step == 0,
                                   video_length=1000)
            obs = rec.reset()
            for _ in range(5):
                obs = rec.step(np.zeros((4, 2), dtype=np.float32))[0]
            self.assertEqual(len(rec.recorded_frames), 6)
            self.assertEqual(rec.recorded_frames[-1].shape, (960, 960, 3))
            self.assertGreater(int(np.ptp(rec.recorded_frames[-1])), 0, "a blank picture")
            rec.recorded_frames = []
            rec.recording = False


if __name__ == "__main__":
    unittest.main()
