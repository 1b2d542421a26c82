"""MJCF (MuJoCo) arms wherever a URDF is taken (#47): `testbed.Robot`,
`testbed.sim` (equal to the CLI bit for bit) and the Gymnasium
environment with robot=..."""

import tempfile
import unittest
from pathlib import Path

import numpy as np

import testbed
from helpers import ROOT, assert_bits, cli_sim, joint

UR5E = ROOT / "robots/menagerie/universal_robots_ur5e/ur5e.xml"


class MjcfRobot(unittest.TestCase):
    def test_robot_reads_the_menagerie_ur5e(self):
        r = testbed.Robot(str(UR5E))
        self.assertEqual(r.dof, 6)
        self.assertEqual(r.joint_names[0], "shoulder_pan_joint")
        # Effort limits from the position servos' force ranges.
        self.assertTrue(np.array_equal(r.effort, [150, 150, 150, 28, 28, 28]))
        q = np.array([-1.5708, -1.5708, 1.5708, -1.5708, -1.5708, 0.0])
        m = r.mass_matrix(q)
        self.assertTrue(np.allclose(m, m.T, rtol=0, atol=1e-12))
        # Armature 0.1 on every joint is on M's diagonal.
        self.assertTrue(np.all(np.diag(m) > 0.1))
        self.assertTrue(np.all(np.linalg.eigvalsh(m) > 0))

    def test_an_mjcf_that_includes_another_file(self):
        r = testbed.Robot(str(ROOT / "arm-model/tests/data/includes_defaults.xml"))
        self.assertEqual(r.joint_names, ["a1", "a2", "a3"])

    def test_a_refused_mjcf_says_why(self):
        with self.assertRaisesRegex(testbed.TestbedError, "floating base"):
            testbed.Robot(str(ROOT / "arm-model/tests/data/free_joint.xml"))


class MjcfSim(unittest.TestCase):
    def test_sim_of_an_mjcf_arm_equals_the_cli(self):
        with tempfile.TemporaryDirectory() as tmp:
            cols, summary = cli_sim(Path(tmp), "--robot", UR5E, "--duration", "0.3")
        rows, mine = testbed.sim(robot=str(UR5E), duration=0.3)
        self.assertEqual(rows["q"].shape, (300, 6))
        for stem, name in {"q": "q", "tau": "tau", "qref": "q_d"}.items():
            assert_bits(self, rows[name], joint(cols, stem, 6), name)
        self.assertEqual(mine["metrics"], summary["metrics"])
        # The default scenario starts at the keyframe home.
        self.assertTrue(np.allclose(rows["q"][0], [-1.5708, -1.5708, 1.5708, -1.5708, -1.5708, 0.0],
                                    atol=0.05))


class MjcfEnv(unittest.TestCase):
    def test_the_env_takes_an_mjcf_robot(self):
        env = testbed.ArmTrackingEnv(robot=str(UR5E))
        obs, _ = env.reset(seed=3)
        self.assertEqual(env.action_space.shape, (6,))
        for _ in range(20):
            obs, reward, terminated, truncated, _ = env.step(env.action_space.sample() * 0)
        self.assertTrue(np.all(np.isfinite(obs)))
        self.assertTrue(np.isfinite(reward))


if __name__ == "__main__":
    unittest.main()
