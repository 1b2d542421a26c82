"""The wheel stands alone: built by maturin (cargo's dev profile, which
reuses the test build, stripped), installed into a fresh virtual
environment in a temporary folder, and used from outside the checkout
with no PYTHONPATH: shipped scenarios and robots by name, `sim`, the
Gymnasium environment, and no path into the checkout anywhere.

The release wheel's size (≤ 30 MB) is measured by hand, as docs/python.md
says: a release build is too slow for CI."""

import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
PROJECT = ROOT / "python/inprocess"

#: Run by the fresh environment's python, in the temporary folder.
CHECK = r"""
import json, sys
from pathlib import Path
import gymnasium, numpy as np
import testbed

venv = Path(sys.argv[1]).resolve()
inside = lambda p: Path(p).resolve().is_relative_to(venv)
assert inside(testbed.__file__), testbed.__file__

rows, summary = testbed.sim(scenario="paper", duration=0.2)
assert rows["q"].shape == (200, 2), rows["q"].shape
assert inside(summary["scenario_source"]), summary["scenario_source"]
# A scenario that names its robot and a CSV by relative paths.
_, s = testbed.sim(scenario="iiwa_csv", duration=0.05)
assert inside(s["scenario_source"]) and inside(s["robot"]), s

env = gymnasium.make("testbed/ArmTracking-v0")
obs, _ = env.reset(seed=0)
for _ in range(5):
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
assert np.isfinite(obs).all() and reward <= 0.0

robot = testbed.Robot("iiwa14")
assert robot.dof == 7, robot.dof
env = gymnasium.make("testbed/ArmTracking-v0", robot="iiwa14")
assert inside(env.unwrapped.core.robot), env.unwrapped.core.robot

# Every shipped scenario and robot loads from the wheel.
assert len(testbed.SCENARIOS) > 10 and len(testbed.ROBOTS) > 5
for name in testbed.SCENARIOS:
    testbed.scenario_toml(name)
for name in testbed.ROBOTS:
    testbed.Robot(name)
# The controller package comes with the wheel (testbed.policy_node imports
# it); reading a log needs no iceoryx2, and `run` without it says what to install.
import testbed_controller, testbed_controller.log, testbed.policy_node
assert inside(testbed_controller.log.__file__), testbed_controller.log.__file__
assert "iceoryx2" not in sys.modules
try:
    testbed_controller.run
    raise AssertionError("run imported without iceoryx2")
except ModuleNotFoundError as e:
    assert "rl-deferred-testbed[bus]" in str(e), e
print(json.dumps({"scenarios": len(testbed.SCENARIOS), "robots": len(testbed.ROBOTS)}))
"""


def run(cmd, **kw):
    out = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=1800, **kw)
    if out.returncode != 0:
        raise AssertionError(f"{' '.join(map(str, cmd))} failed ({out.returncode}):\n"
                             f"{out.stdout[-2000:]}\n{out.stderr[-4000:]}")
    return out


class StandaloneWheel(unittest.TestCase):
    def test_the_wheel_works_in_a_fresh_venv_outside_the_checkout(self):
        maturin = Path(sys.executable).parent / "maturin"
        self.assertTrue(maturin.exists(), f"no maturin beside {sys.executable}: bash python/build-module.sh")
        with tempfile.TemporaryDirectory(prefix="testbed-wheel-") as tmp:
            tmp = Path(tmp)
            env = dict(os.environ, VIRTUAL_ENV=str(Path(sys.executable).parents[1]))
            run([maturin, "build", "--quiet", "--profile", "dev", "--strip", "-i", sys.executable,
                 "-o", tmp / "wheels"], cwd=PROJECT, env=env)
            wheels = list((tmp / "wheels").glob("rl_deferred_testbed-*.whl"))
            self.assertEqual(len(wheels), 1, wheels)
            size = wheels[0].stat().st_size
            self.assertLess(size, 30 * 2**20, f"{wheels[0].name}: {size / 2**20:.1f} MB")
            venv = tmp / "venv"
            run([sys.executable, "-m", "venv", venv])
            python = venv / "bin/python"
            clean = {k: v for k, v in os.environ.items()
                     if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
            run([python, "-m", "pip", "install", "--quiet", "--disable-pip-version-check", wheels[0]],
                env=clean, cwd=tmp)
            out = run([python, "-c", CHECK, venv], env=clean, cwd=tmp)
            self.assertIn('"robots"', out.stdout)


if __name__ == "__main__":
    unittest.main()
