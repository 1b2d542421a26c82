"""The shipped Stable-Baselines3 examples, run briefly in the environment
with SB3 and torch (as test_sb3.py finds or makes it): train_sb3.py,
export_sb3_onnx.py on what it saved, and train_lagrangian.py. Never
skipped: without such an environment this test fails and says why."""

import json
import os
import re
import subprocess
import tempfile
import unittest
from pathlib import Path

from test_sb3 import HERE, ROOT, sb3_python

EXAMPLES = ROOT / "python/examples"


def run_example(python: str, name: str, *args: str, cwd: str) -> str:
    """Runs an example with this checkout's module first; its stdout."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(HERE.parent)] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    out = subprocess.run([python, str(EXAMPLES / name), *args], cwd=cwd, env=env,
                         capture_output=True, text=True, timeout=1800)
    if out.returncode != 0:
        raise AssertionError(f"{name} {' '.join(args)} exited {out.returncode}:\n{out.stderr[-4000:]}")
    return out.stdout


class ShippedExamples(unittest.TestCase):
    def test_train_sb3_and_its_onnx_export_run(self):
        python = sb3_python()
        with tempfile.TemporaryDirectory() as d:
            # --smooth: the shipped smooth policy's settings, which the
            # export must carry into the record (#59 item 1).
            out = run_example(python, "train_sb3.py", "--timesteps", "1024", "--n-envs", "4",
                              "--eval-seeds", "1", "--out", "ppo", "--smooth", cwd=d)
            self.assertRegex(out, r"pd alone: +mean return -?\d+\.\d+, constraint cost \d+ steps")
            self.assertRegex(out, r"PPO on pd: +mean return -?\d+\.\d+, constraint cost \d+ steps")
            self.assertTrue((Path(d) / "ppo.zip").is_file(), out)
            out = run_example(python, "export_sb3_onnx.py", "ppo.zip", "ppo.onnx", cwd=d)
            # The exported network is SB3's deterministic action.
            m = re.search(r"max \|torch - predict\| = (\S+)", out)
            self.assertIsNotNone(m, out)
            self.assertLess(float(m.group(1)), 1e-6, out)
            self.assertGreater((Path(d) / "ppo.onnx").stat().st_size, 1000)
            import onnx
            props = {p.key: p.value for p in onnx.load(str(Path(d) / "ppo.onnx")).metadata_props}
            record = json.loads(props["testbed.env"])
            self.assertEqual((record["smoothing"], record["observe_action"], record["obs_dim"]),
                             ("ramp", True, 17))
            # Without the settings file the export refuses rather than guess.
            (Path(d) / "ppo.env.json").unlink()
            env = dict(os.environ, PYTHONPATH=str(HERE.parent))
            bad = subprocess.run([python, str(EXAMPLES / "export_sb3_onnx.py"), "ppo.zip", "x.onnx"],
                                 cwd=d, env=env, capture_output=True, text=True, timeout=600)
            self.assertNotEqual(bad.returncode, 0)
            self.assertIn("ppo.env.json is missing", bad.stderr)

    def test_train_lagrangian_moves_lambda_with_the_cost(self):
        python = sb3_python()
        with tempfile.TemporaryDirectory() as d:
            out = run_example(python, "train_lagrangian.py", "--timesteps", "8192", "--n-envs", "16",
                              "--eval-seeds", "1", "--out", "lag", cwd=d)
            rollouts = [(float(r), float(lam)) for r, lam in
                        re.findall(r"cost rate (\S+), lambda (\S+)", out)]
            self.assertGreaterEqual(len(rollouts), 2, out)
            # pd at K/16 breaks the envelope at first, so the cost rate is
            # above the budget 0 and dual ascent raises lambda by lr * rate.
            first_rate, first_lam = rollouts[0]
            self.assertGreater(first_rate, 0.0, out)
            # Both are printed rounded: lambda to 3 decimals, the rate to 4.
            self.assertAlmostEqual(first_lam, 5.0 * first_rate, delta=0.0005 + 5.0 * 0.00005)
            self.assertGreater(rollouts[-1][1], 0.0, out)
            self.assertRegex(out, r"PPO-Lagrangian: +mean return -?\d+\.\d+, constraint cost \d+ steps")


if __name__ == "__main__":
    unittest.main()
