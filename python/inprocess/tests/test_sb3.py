"""The Stable-Baselines3 adapter (testbed.sb3), checked in an environment
with SB3 and torch: TESTBED_SB3_PYTHON if set, else the one
python/setup-train-venv.sh makes (made here if missing). Never skipped:
without such an environment this test fails and says why."""

import os
import subprocess
import unittest
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]


def sb3_python() -> str:
    given = os.environ.get("TESTBED_SB3_PYTHON")
    if given:
        if not Path(given).exists():
            raise AssertionError(f"TESTBED_SB3_PYTHON = {given}: no such file")
        return given
    # The script is a no-op when the environment is there.
    out = subprocess.run(["bash", str(ROOT / "python/setup-train-venv.sh")], capture_output=True,
                         text=True, timeout=3600)
    if out.returncode != 0:
        raise AssertionError("no Stable-Baselines3 environment: python/setup-train-venv.sh failed "
                             f"({out.returncode}); set TESTBED_SB3_PYTHON to a python with "
                             f"stable-baselines3, torch and gymnasium 1.4.0.\n{out.stderr[-3000:]}")
    return out.stdout.strip().splitlines()[-1]


class StableBaselines3(unittest.TestCase):
    def test_the_sb3_adapter_passes_its_checks_under_sb3(self):
        python = sb3_python()
        env = dict(os.environ)
        # This checkout's module first, whatever the environment's .pth says.
        env["PYTHONPATH"] = os.pathsep.join(
            [str(HERE.parent)] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
        out = subprocess.run([python, "-m", "unittest", "-v", "sb3_checks"], cwd=HERE, env=env,
                             capture_output=True, text=True, timeout=1800)
        err = out.stderr
        self.assertEqual(out.returncode, 0, f"{python} -m unittest sb3_checks:\n{err[-6000:]}")
        self.assertNotIn("skipped", err)
        self.assertRegex(err, r"Ran [1-9]\d* tests")
        self.assertIn("\nOK", err)


if __name__ == "__main__":
    unittest.main()
