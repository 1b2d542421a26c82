"""What an adversary tried (a review of the module): threads, self-nesting
`set=` values, huge sizes, bytes for arrays, stepping past the end, and
hostile policy files. Each gives a Python exception naming the cause."""

import subprocess
import sys
import tempfile
import threading
import unittest
from pathlib import Path

import gymnasium
import numpy as np

import testbed
from testbed.policy import LinearPolicy

ENV = testbed.ENV_ID


class Boundary(unittest.TestCase):
    def test_an_env_made_in_one_thread_steps_in_another(self):
        env = gymnasium.make(ENV, duration=0.01)
        env.reset(seed=0)
        out = []
        t = threading.Thread(target=lambda: out.append(env.step(np.zeros(2, np.float32))))
        t.start()
        t.join()
        self.assertEqual(len(out), 1)
        venv = testbed.VecEnvCore(2)
        venv.reset(0)
        t = threading.Thread(target=lambda: out.append(venv.step(np.zeros((2, 2)))))
        t.start()
        t.join()
        self.assertEqual(len(out), 2)

    def test_a_set_value_that_contains_itself(self):
        loop = []
        loop.append(loop)
        with self.assertRaisesRegex(ValueError, "nested more than 16 deep"):
            testbed.sim(set={"controller.k1": loop})
        d = {}
        d["a"] = d
        with self.assertRaisesRegex(ValueError, "nested more than 16 deep"):
            testbed.sim(set={"controller": d})

    def test_a_refused_set_quotes_its_value_cut(self):
        """#48 item 9 (N7): a 2 M-entry set= made a 10 MB message."""
        long = "k" * 1_000_000
        for set_ in ([long], {"controller.k1": [1.0] * 200_000 + ["x"]}, {long: 1}):
            try:
                testbed.sim(set=set_, duration=0.01)
            except (ValueError, TypeError, testbed.TestbedError) as e:
                self.assertLess(len(str(e)), 2000, str(e)[:2000])
                self.assertIn("bytes in all)", str(e))
            else:
                self.fail("accepted")

    def test_huge_sizes_are_refused_before_anything_is_allocated(self):
        for n in (0, 2**62):
            with self.assertRaisesRegex(testbed.TestbedError, "num_envs = .* must be from 1 to 65536"):
                testbed.VecEnvCore(n)
        with self.assertRaises(TypeError):
            gymnasium.make_vec(ENV, num_envs=2.7)
        with self.assertRaisesRegex(testbed.TestbedError, "GB of rows"):
            testbed.sim(duration=1e5)
        with self.assertRaisesRegex(testbed.TestbedError, "at most 10000 seeds"):
            testbed.compare(seeds=2**63, duration=0.01)
        # A thread count past four per CPU is cut, as the CLI cuts it.
        table = testbed.compare(laws=["pd"], duration=0.01, threads=10**6)
        self.assertLessEqual(table["threads"], 4 * 1024)

    def test_bytes_and_strings_are_not_numbers(self):
        env = gymnasium.make(ENV)
        env.reset(seed=0)
        for bad in (b"ab", "ab"):
            with self.assertRaisesRegex(TypeError, "expected 2 numbers"):
                env.step(bad)
        with self.assertRaisesRegex(TypeError, "expected 2 numbers"):
            testbed.Robot().gravity(b"\0\0")

    def test_the_raw_core_stops_at_the_episodes_end(self):
        core = testbed.EnvCore(duration=0.002, decimation=1)
        core.reset(0)
        core.step(np.zeros(2))
        *_, truncated, _ = core.step(np.zeros(2))
        self.assertTrue(truncated)
        with self.assertRaisesRegex(RuntimeError, "call reset"):
            core.step(np.zeros(2))
        core.reset(1)
        core.step(np.zeros(2))

    def test_dynamics_that_overflow_raise(self):
        with self.assertRaisesRegex(ValueError, "not finite"):
            testbed.Robot().coriolis([0.1, 0.2], [1e300, 1e300])

    def test_a_vector_reset_takes_a_list_of_seeds(self):
        venv = gymnasium.make_vec(ENV, num_envs=3)
        a, _ = venv.reset(seed=[5, 6, 7])
        b, _ = venv.reset(seed=5)
        self.assertTrue(np.array_equal(a, b))
        with self.assertRaisesRegex(ValueError, "seed must be"):
            venv.reset(seed=[5, 9, 7])


class ActionTypes(unittest.TestCase):
    """#48 item 14 (N13): actions that would be read silently wrong are
    refused by every step, naming the dtype; float32, float64 and
    integers are taken."""

    BAD = {"complex": np.complex128, "bool": np.bool_, "float16": np.float16}

    def test_complex_bool_and_float16_actions_are_refused(self):
        env = gymnasium.make(testbed.ENV_ID, scenario="paper", episode_s=0.1)
        vec = testbed.ArmTrackingVecEnv(2, scenario="paper", episode_s=0.1, num_threads=1)
        env.reset(seed=1)
        vec.reset(seed=1)
        for name, dtype in self.BAD.items():
            with self.subTest(dtype=name):
                with self.assertRaisesRegex(TypeError, f"dtype {np.dtype(dtype)} is refused"):
                    env.unwrapped.step(np.zeros(2, dtype))
                with self.assertRaisesRegex(TypeError, f"dtype {np.dtype(dtype)} is refused"):
                    vec.step(np.zeros((2, 2), dtype))
        for good in (np.zeros(2, np.float32), np.zeros(2), np.zeros(2, np.int64), [0, 0]):
            env.unwrapped.step(good)
        vec.step(np.zeros((2, 2), np.float32))


class PolicyFiles(unittest.TestCase):
    def node(self, path):
        return subprocess.run([sys.executable, "-m", "testbed.policy_node", "--policy", str(path),
                               "--describe"], capture_output=True, text=True, timeout=120)

    def test_hostile_policy_files_fail_in_one_line(self):
        env = {"dof": 2, "obs_dim": 15, "steps": 100, "torque_scale": [1.0, 1.0]}
        cases = {
            "shape.npz": dict(weights=np.zeros((2, 3)), bias=np.zeros(2), env=str(env).replace("'", '"')),
            "rows.npz": dict(weights=np.zeros((3, 15)), bias=np.zeros(3), env=str(env).replace("'", '"')),
            "nan.npz": dict(weights=np.full((2, 15), np.nan), bias=np.zeros(2),
                            env=str(env).replace("'", '"')),
            "steps.npz": dict(weights=np.zeros((2, 15)), bias=np.zeros(2),
                              env=str({**env, "steps": 0}).replace("'", '"')),
            "law.npz": dict(weights=np.zeros((2, 15)), bias=np.zeros(2),
                            env=str({**env, "base_law": "rm -rf"}).replace("'", '"')),
            "string.npz": dict(weights=np.zeros((2, 15)), bias=np.zeros(2), env='"dof obs_dim"'),
            "pickle.npz": dict(weights=np.array([object()], dtype=object), bias=np.zeros(2),
                               env="{}"),
        }
        with tempfile.TemporaryDirectory() as tmp:
            garbage = Path(tmp) / "garbage.npz"
            garbage.write_bytes(b"not a zip file")
            paths = [garbage]
            for name, arrays in cases.items():
                path = Path(tmp) / name
                np.savez(path, **arrays)
                paths.append(path)
            for path in paths:
                out = self.node(path)
                self.assertNotEqual(out.returncode, 0, path.name)
                self.assertIn(f"testbed.policy_node: {path}:", out.stderr, path.name)
                self.assertNotIn("Traceback", out.stderr, f"{path.name}: {out.stderr}")

    def test_a_policy_array_over_the_cap_is_refused_before_it_is_read(self):
        """#48 item 9 (N9): an .npz whose .npy header declares 3.2 GB is
        refused from the header, naming the member and the cap, before
        numpy allocates it."""
        import io
        import zipfile

        from testbed.policy import MAX_POLICY_ARRAY_BYTES

        def npy(array=None, header=None):
            out = io.BytesIO()
            if header is None:
                np.lib.format.write_array(out, array)
            else:
                np.lib.format.write_array_header_1_0(out, header)
                out.write(b"\0" * 64)
            return out.getvalue()

        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "bomb.npz"
            with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
                z.writestr("weights.npy", npy(header={"descr": "<f8", "fortran_order": False,
                                                      "shape": (20000, 20000)}))
                z.writestr("bias.npy", npy(np.zeros(2)))
                z.writestr("env.npy", npy(np.array("{}")))
            with self.assertRaises(ValueError) as caught:
                LinearPolicy.load(path)
            message = str(caught.exception)
            self.assertIn(f"{path}: member 'weights.npy' declares shape (20000, 20000)", message)
            self.assertIn(f"over the cap of {MAX_POLICY_ARRAY_BYTES} bytes", message)

    def test_a_good_policy_file_describes_itself(self):
        p = LinearPolicy.zeros(2, 15, {"dof": 2, "obs_dim": 15, "steps": 100,
                                        "torque_scale": [1.0, 1.0], "base_law": "pd"})
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "ok.npz"
            p.save(path)
            out = self.node(path)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn('"name": "policy"', out.stdout)


class HostileUse(unittest.TestCase):
    """#60 items 6 and 11: a set= key that is TOML text, a start far past
    any posture, steps out of Gymnasium's order, threads on one env."""

    def test_a_set_key_is_a_dotted_name_never_toml_text(self):
        for key in ("controller.k1=20 #", "controller.k1\nduration_s", "controller..k1", ""):
            with self.assertRaises(ValueError) as e:
                testbed.sim(set={key: 5.0}, duration=0.01)
            self.assertIn("not a dotted name", str(e.exception))
        # A good key still works, with its typed value.
        _, s = testbed.sim(set={"controller.k1": 20.0}, duration=0.01)
        self.assertTrue(s["finite"])

    def test_a_start_beyond_any_posture_is_refused_by_name(self):
        env = gymnasium.make(ENV, duration=0.01)
        for opts in ({"initial_q": [1e300, 0]}, {"initial_qd": [0, -2e3]}):
            with self.assertRaises(testbed.TestbedError) as e:
                env.reset(seed=0, options=opts)
            self.assertIn("within ±1000", str(e.exception))
        env.reset(seed=0, options={"initial_q": [0.5, 1.0]})

    def test_step_before_reset_and_after_close_are_refused(self):
        for env, action in ((testbed.ArmTrackingEnv(duration=0.01), np.zeros(2)),
                            (testbed.ArmTrackingVecEnv(2, duration=0.01), np.zeros((2, 2)))):
            with self.assertRaises(RuntimeError) as e:
                env.step(action)
            self.assertIn("before reset()", str(e.exception))
            env.reset(seed=0)
            env.step(action)
            env.close()
            for call in (lambda: env.step(action), lambda: env.reset(seed=1)):
                with self.assertRaises(RuntimeError) as e:
                    call()
                self.assertIn("after close()", str(e.exception))
        core = testbed.EnvCore(duration=0.01)
        with self.assertRaises(RuntimeError) as e:
            core.step(np.zeros(2))
        self.assertIn("before reset()", str(e.exception))

    def test_threads_sharing_one_vector_env_are_told_what_to_do(self):
        env = testbed.ArmTrackingVecEnv(64, duration=5.0)
        env.reset(seed=0)
        errors, ok = [], []

        def work():
            for _ in range(200):
                try:
                    env.step(np.zeros((64, 2)))
                    ok.append(1)
                except RuntimeError as e:
                    errors.append(str(e))

        threads = [threading.Thread(target=work) for _ in range(8)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        self.assertTrue(ok)
        for e in errors:
            self.assertNotIn("Already borrowed", e)
            self.assertIn("give each thread its own environment", e)


if __name__ == "__main__":
    unittest.main()
