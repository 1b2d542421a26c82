"""The loop closed: a dependency-free learner improves its return, and the
learnt policy runs as the controller node of a lockstep run (the env's
episode, bit for bit) and as a row of `testbed compare`."""

import json
import sys
import tempfile
import unittest
from pathlib import Path

import gymnasium
import numpy as np

import testbed
from testbed.policy import LinearPolicy, env_record, episode_return, random_search
from helpers import assert_bits, joint, run_testbed

# Torque mode on the paper's arm, 0.5 s episodes: with no torque the arm
# falls, so a policy has to learn to hold it on the reference.
KWARGS = {"scenario": "paper", "duration": 0.5, "torque_scale": [20.0, 5.0],
          "breach_factor": None}


def node_cmd(policy_path) -> str:
    return f"{sys.executable} -m testbed.policy_node --policy {policy_path}"


class Learner(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.env = gymnasium.make(testbed.ENV_ID, **KWARGS)
        core = cls.env.unwrapped.core
        start = LinearPolicy.zeros(core.dof, core.obs_dim, {**KWARGS, **env_record(cls.env)})
        cls.before = episode_return(cls.env, start, seed=0)
        cls.history = []
        cls.policy = random_search(cls.env, start, iterations=8, directions=8, top=4,
                                   step_size=0.05, noise=0.05, seed=1,
                                   callback=lambda it, r: cls.history.append(r))
        cls.after = episode_return(cls.env, cls.policy, seed=0)
        cls.tmp = tempfile.TemporaryDirectory()
        cls.path = Path(cls.tmp.name) / "policy.npz"
        cls.policy.save(cls.path)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_random_search_improves_the_return(self):
        self.assertLess(self.before, -50.0, "with no torque the arm falls")
        self.assertGreater(self.after, self.before + 0.5 * abs(self.before),
                           f"return {self.before:.1f} -> {self.after:.1f} ({self.history})")

    def test_the_policy_file_round_trips(self):
        back = LinearPolicy.load(self.path)
        assert_bits(self, back.weights, self.policy.weights, "weights")
        self.assertEqual(back.env["torque_scale"], [20.0, 5.0])
        bad = Path(self.tmp.name) / "bad.npz"
        np.savez(bad, weights=np.zeros((2, 3)))
        with self.assertRaisesRegex(ValueError, "not a testbed policy file"):
            LinearPolicy.load(bad)

    def test_the_policy_as_a_lockstep_controller_is_the_env_episode(self):
        out = Path(self.tmp.name) / "lockstep"
        csv_path = out / "run.csv"
        out.mkdir()
        run = run_testbed("run", "--mode", "lockstep", "--duration", "0.5", "--json",
                          "--runs-dir", out, "--csv", csv_path,
                          "--controller-cmd", node_cmd(self.path))
        report = json.loads(run.stdout)
        self.assertEqual(report["controller_law"]["name"], "policy")
        import csv
        with open(csv_path, newline="") as f:
            rows = list(csv.reader(f))
        cols = {h: np.array([float(r[i]) for r in rows[1:]]) for i, h in enumerate(rows[0])}
        q_run = joint(cols, "q", 2)
        obs, _ = self.env.reset(seed=0)
        core = self.env.unwrapped.core
        qs = []
        for _ in range(core.decisions):
            obs, *_ = self.env.step(self.policy.act(obs))
            qs.append(core.true_state[0])
        # Decision j leaves the state of plant period d·(j + 1), d = 20.
        d = core.decimation
        self.assertEqual(d, 20)
        assert_bits(self, np.array(qs)[:-1], q_run[d::d], "q of the env and of the lockstep run")

    def test_the_policy_is_a_row_of_compare(self):
        run = run_testbed("compare", "--scenario", "paper", "--duration", "2.5", "--seeds", "1",
                          "--laws", "pd", "--json", "--runs-dir", self.tmp.name,
                          "--controller-cmd", f"policy={node_cmd(self.path)}")
        table = json.loads(run.stdout)
        names = [row["name"] for row in table["laws"]]
        self.assertEqual(names, ["pd", "policy"])
        policy_row = table["laws"][1]
        self.assertEqual(policy_row["external"]["declared"]["name"], "policy")
        [run] = policy_row["runs"]
        # Scored like any law: a summary of the whole run, and a failure
        # named when it has one (trained on 0.5 s, it is run for 2.5 s).
        self.assertEqual(run["summary"]["steps"], 2500)
        self.assertTrue(np.isfinite(run["summary"]["metrics"]["iae_after_tc"]))
        self.assertTrue(run["summary"]["finite"])
        self.assertIn(run["failure"], (None, "left the envelope after T_c"))


if __name__ == "__main__":
    unittest.main()
