"""A policy file names its scenario: only a shipped one or its own embedded
TOML is read, and no file it names is ever quoted (issue 48, N2); a policy
trained on another scenario or period is refused by name in a run it does
not fit (issue 48, N8)."""

import json
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import gymnasium
import numpy as np

import testbed
from testbed.policy import LinearPolicy, env_record
from helpers import ROOT, testbed_bin

SECRET = "SECRET-LINE-48: never quoted"


def paper_env(**extra) -> dict:
    """The env record of a residual policy on pd over 0.1 s of the paper's scenario."""
    kwargs = {"scenario": "paper", "duration": 0.1, "base_law": "pd", **extra}
    env = gymnasium.make(testbed.ENV_ID, **kwargs)
    return {**kwargs, **env_record(env)}


class PolicyScenario(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)
        self.secret = self.dir / "secret.toml"
        self.secret.write_text(SECRET + "\n")

    def tearDown(self):
        self.tmp.cleanup()

    def save(self, name, env) -> Path:
        path = self.dir / name
        # Saved as a file a hostile author writes: no check on the way out.
        np.savez(path, weights=np.zeros((2, 15)), bias=np.zeros(2), env=json.dumps(env))
        return path

    def node_cmd(self, path) -> str:
        return f"{sys.executable} -m testbed.policy_node --policy {path}"

    def run_lockstep(self, path) -> subprocess.CompletedProcess:
        runs = self.dir / "runs"
        return subprocess.run([testbed_bin(), "run", "--mode", "lockstep", "--duration", "0.1",
                               "--json", "--runs-dir", str(runs),
                               "--controller-cmd", self.node_cmd(path)],
                              cwd=ROOT, capture_output=True, text=True, timeout=300)

    def everything_said(self, out) -> str:
        """stderr, stdout and every node log the run left."""
        logs = [p.read_text(errors="replace") for p in (self.dir / "runs").rglob("*.log")]
        return "\n".join([out.stderr, out.stdout, *logs])

    def test_a_policy_naming_a_file_is_refused_without_quoting_it(self):
        base = paper_env()
        toml = (ROOT / "scenarios/paper.toml").read_text()
        cases = {
            "scenario.npz": {**base, "scenario": str(self.secret)},
            "set.npz": {**base, "set": [f"reference.file={self.secret}"]},
            "embedded.npz": {**{k: v for k, v in base.items() if k != "scenario"},
                             "scenario_toml": toml + f'\n[reference]\nfile = "{self.secret}"\n'},
        }
        for name, env in cases.items():
            path = self.save(name, env)
            with self.assertRaises(ValueError, msg=name) as e:
                LinearPolicy.load(path)
            self.assertNotIn("SECRET", str(e.exception), name)
            out = self.run_lockstep(path)
            self.assertNotEqual(out.returncode, 0, name)
            said = self.everything_said(out)
            self.assertNotIn("SECRET", said, name)
            self.assertRegex(said, r"env\.(scenario|set|scenario_toml)", name)
        # A robot that is no URDF: the base law cannot be built, unquoted.
        robot = self.dir / "secret.urdf"
        robot.write_text(SECRET + "\n")
        out = self.run_lockstep(self.save("robot.npz", {**base, "robot": str(robot)}))
        self.assertNotEqual(out.returncode, 0)
        said = self.everything_said(out)
        self.assertNotIn("SECRET", said)
        self.assertIn("env.robot", said)

    def test_a_policy_embedding_its_scenario_runs(self):
        base = {k: v for k, v in paper_env().items() if k != "scenario"}
        toml = (ROOT / "scenarios/paper.toml").read_text()
        out = self.run_lockstep(self.save("own.npz", {**base, "scenario_toml": toml}))
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(json.loads(out.stdout)["controller_law"]["name"], "policy")

    def test_a_policy_from_another_scenario_or_period_is_refused_by_name(self):
        # Trained with k1 = 1 (the tight_envelope policy), run on the paper's k1 = 15.
        k1 = paper_env(scenario="tight_envelope", set=["controller.k1=1"])
        self.assertEqual(k1["controller"]["k1"], 1.0)
        out = self.run_lockstep(self.save("k1.npz", k1))
        self.assertNotEqual(out.returncode, 0)
        said = self.everything_said(out)
        self.assertIn("controller.k1 = 1.0", said)
        self.assertIn("controller.k1 is 15.0", said)
        # A file from before the record: the base law's own parameters say it.
        old = {k: v for k, v in k1.items() if k not in ("controller", "period_ns")}
        said = self.everything_said(self.run_lockstep(self.save("old.npz", old)))
        self.assertIn("controller.k1 = 1.0", said)
        # Another control period.
        period = {**paper_env(), "period_ns": 2_000_000}
        out = self.run_lockstep(self.save("period.npz", period))
        self.assertNotEqual(out.returncode, 0)
        said = self.everything_said(out)
        self.assertIn("2000000 ns (env.period_ns); this run's is 1000000 ns", said)
        # The policy's own scenario and period: it runs.
        out = self.run_lockstep(self.save("same.npz", paper_env()))
        self.assertEqual(out.returncode, 0, out.stderr)


if __name__ == "__main__":
    unittest.main()


class SmoothedRecord(unittest.TestCase):
    """#59 item 1: the record carries the smoothing; the Rust node plays it,
    the Python node refuses it rather than play a held action."""

    def test_the_record_carries_the_smoothing_and_the_python_node_refuses_it(self):
        from testbed.policy_node import PolicyController
        env = paper_env(smoothing="low-pass", smoothing_tau_s=0.01, observe_action=True)
        self.assertEqual((env["smoothing"], env["smoothing_tau_s"], env["observe_action"]),
                         ("low-pass", 0.01, True))
        self.assertEqual(env["obs_dim"], 17)
        policy = LinearPolicy.zeros(2, 17, env)
        policy.check()
        with self.assertRaisesRegex(ValueError, "this Python node plays held actions"):
            PolicyController(policy)
        with self.assertRaisesRegex(ValueError, "env.obs_dim = 15; an arm of 2 joints, its last action observed,"):
            LinearPolicy.zeros(2, 15, dict(env, obs_dim=15)).check()
        with self.assertRaisesRegex(ValueError, "env.smoothing_tau_s = None"):
            LinearPolicy.zeros(2, 17, dict(env, smoothing_tau_s=None)).check()
        # A held record is played by either node.
        held = paper_env()
        self.assertEqual((held["smoothing"], held["observe_action"]), ("hold", False))
        PolicyController(LinearPolicy.zeros(2, 15, held))
