"""`testbed.sim` and `testbed.compare` against the CLI, and robots' dynamics."""

import itertools
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

import numpy as np

import testbed
from helpers import ROOT, assert_bits, cli_sim, joint, run_testbed

# Summary fields that are timings of this machine, not results.
TIMED = {"wall_time_s", "realtime_factor", "compute_us"}

# CSV stems and the arrays sim returns, same rows.
STEMS = {"q": "q", "qd": "qd", "qdd": "qdd", "tau": "tau", "qref": "q_d", "kc": "kc",
         "z1_": "z1", "z2_": "z2", "wa": "wa_norm", "qm": "q_measured",
         "qdm": "qd_measured", "d": "disturbance"}


class SimEqualsCli(unittest.TestCase):
    def check(self, cli_args, **kwargs):
        with tempfile.TemporaryDirectory() as tmp:
            cols, summary = cli_sim(Path(tmp), *cli_args)
        rows, mine = testbed.sim(**kwargs)
        n = rows["q"].shape[1]
        assert_bits(self, rows["t"], cols["t"], "t")
        for stem, name in STEMS.items():
            assert_bits(self, rows[name], joint(cols, stem, n), name)
        self.assertTrue(np.array_equal(rows["effects"], cols["effects"].astype(np.uint32)))
        for key in summary:
            if key not in TIMED:
                self.assertEqual(mine[key], summary[key], key)
        return rows, mine

    def test_the_paper_scenario(self):
        rows, summary = self.check(["--duration", "3"], duration=3.0)
        self.assertEqual(rows["q"].shape, (3000, 2))
        self.assertEqual(summary["law"]["law"], "nac")

    def test_noise_and_overrides_by_name(self):
        self.check(["--scenario", "friction_noise", "--duration", "1", "--set", "seed=7",
                    "--set", "controller.k1=[12.0, 9.0]", "--law", "blf"],
                   scenario="friction_noise", duration=1.0, law="blf",
                   set={"seed": 7, "controller.k1": [12.0, 9.0]})

    def test_a_randomised_six_joint_arm(self):
        self.check(["--scenario", "ur5_randomised", "--duration", "0.5", "--set", "seed=3"],
                   scenario="ur5_randomised", duration=0.5, set=["seed=3"])

    def test_a_robot_alone_runs_its_default_scenario(self):
        urdf = ROOT / "robots/iiwa14.urdf"
        self.check(["--robot", urdf, "--duration", "0.3"], robot=str(urdf), duration=0.3)


class Errors(unittest.TestCase):
    def test_unknown_scenario_names_the_shipped_ones(self):
        with self.assertRaisesRegex(testbed.TestbedError, "not a shipped scenario.*paper"):
            testbed.sim("no_such_scenario")

    def test_a_bad_key_is_named(self):
        with self.assertRaisesRegex(testbed.TestbedError, "controller.beta"):
            testbed.sim(set={"controller.beta": -1.0}, duration=0.1)
        with self.assertRaisesRegex(testbed.TestbedError, "no_such_key"):
            testbed.sim(set={"controller.no_such_key": 1.0}, duration=0.1)

    def test_bad_values_and_laws(self):
        with self.assertRaisesRegex(ValueError, "unknown law 'nope'"):
            testbed.sim(law="nope")
        with self.assertRaises(TypeError):
            testbed.sim(set={"seed": object()})
        with self.assertRaisesRegex(testbed.TestbedError, "broken.urdf"):
            with tempfile.TemporaryDirectory() as tmp:
                bad = Path(tmp) / "broken.urdf"
                bad.write_text("<robot name='x'><link name='a'/>")
                testbed.Robot(str(bad))


class Seeds(unittest.TestCase):
    def test_a_seed_above_i64_max_is_a_seed(self):
        # #48 item 16: a seed is a u64; past 2**63 - 1 it was rounded to a
        # float and refused.
        for seed in (2**63, 2**64 - 1):
            for set_ in ({"seed": seed}, [f"seed={seed}"]):
                rows, _ = testbed.sim("friction_noise", duration=0.01, set=set_)
                self.assertEqual(rows["q"].shape[0], 10)
        a, _ = testbed.sim("friction_noise", duration=0.01, set={"seed": 2**64 - 1})
        b, _ = testbed.sim("friction_noise", duration=0.01, set={"seed": 2**64 - 2})
        self.assertFalse(np.array_equal(a["q"], b["q"]))
        for bad in (2**64, -1):
            with self.assertRaisesRegex(testbed.TestbedError, "seed"):
                testbed.sim(duration=0.01, set={"seed": bad})


class CompareEqualsCli(unittest.TestCase):
    def test_rows_and_scores(self):
        import json
        out = run_testbed("compare", "--scenario", "paper", "--duration", "2.5",
                          "--laws", "nac,pd,ctc", "--json")
        cli = json.loads(out.stdout)
        mine = testbed.compare("paper", laws=["nac", "pd", "ctc"], duration=2.5)
        self.assertEqual([r["name"] for r in mine["laws"]], [r["name"] for r in cli["laws"]])
        for a, b in zip(mine["laws"], cli["laws"]):
            for key, value in b["median"].items():
                if not key.startswith("compute_"):  # this machine's timings
                    self.assertEqual(a["median"][key], value, f"{a['name']} {key}")
            self.assertEqual(a["kept_envelope"], b["kept_envelope"], a["name"])


class RobotDynamics(unittest.TestCase):
    def setUp(self):
        self.robot = testbed.Robot(str(ROOT / "robots/ur5.urdf"))
        self.q = np.array([0.3, -1.1, 1.4, -0.6, 0.8, 0.2])[: self.robot.dof]
        self.qd = np.array([0.5, -0.4, 0.9, 0.3, -0.7, 1.1])[: self.robot.dof]

    def test_description(self):
        r = self.robot
        self.assertEqual(r.dof, len(r.joint_names))
        self.assertTrue(np.all(r.lower < r.upper))
        self.assertTrue(np.all(r.effort > 0))

    def test_mass_matrix_is_symmetric_positive_definite(self):
        m = self.robot.mass_matrix(self.q)
        self.assertTrue(np.allclose(m, m.T, atol=1e-12))
        self.assertTrue(np.all(np.linalg.eigvalsh(m) > 0))

    def test_coriolis_from_the_mass_matrix(self):
        """C(q, q̇)q̇ from the Christoffel symbols of M (central differences):
        c_i = Σ_jk (∂M_ij/∂q_k − ½ ∂M_jk/∂q_i) q̇_j q̇_k."""
        r, q, qd, h = self.robot, self.q, self.qd, 1e-6
        n = r.dof
        dm = np.stack([(r.mass_matrix(q + h * e) - r.mass_matrix(q - h * e)) / (2 * h)
                       for e in np.eye(n)])  # dm[k] = ∂M/∂q_k
        c = np.einsum("kij,j,k->i", dm, qd, qd) - 0.5 * np.einsum("ijk,j,k->i", dm, qd, qd)
        self.assertTrue(np.allclose(r.coriolis(q, qd), c, atol=1e-6), (r.coriolis(q, qd), c))

    def test_gravity_equals_newton_euler(self):
        """G(q) of the engine against the model-based laws' Newton–Euler
        (arm_model): pd-gravity's model term at zero error and speed."""
        law = testbed.Law("pd-gravity", robot=str(ROOT / "robots/ur5.urdf"))
        z = np.zeros(self.robot.dof)
        law.step(0.0, self.q, z, self.q, z, z, np.ones_like(z), z)
        g = law.diagnostics["tau_model"]
        self.assertTrue(np.allclose(self.robot.gravity(self.q), g, rtol=1e-9, atol=1e-9))

    def test_bad_arguments(self):
        with self.assertRaisesRegex(ValueError, "q: 2 values; this arm needs 6"):
            self.robot.mass_matrix([0.0, 1.0])
        with self.assertRaisesRegex(ValueError, r"q\[1\] = NaN"):
            self.robot.gravity([0.0, float("nan"), 0, 0, 0, 0])
        with self.assertRaisesRegex(TypeError, "expected 6 numbers"):
            self.robot.gravity("abcdef")


class Laws(unittest.TestCase):
    def test_the_rust_law_replays_a_run(self):
        """Law("nac") stepped on a run's states gives the run's torques."""
        rows, _ = testbed.sim(duration=1.0, set={"plant.saturate": False})
        law = testbed.Law("nac")
        rows_ref = rows
        for k in range(len(rows["t"])):
            # q̈_d and k̇_c are not in the rows: nac reads them through the
            # reference sample only in its feed-forward, which the paper's law has not.
            tau = law.step(rows_ref["t"][k], rows["q_measured"][k], rows["qd_measured"][k],
                           rows["q_d"][k], rows["qd_d"][k], np.zeros(2), rows["kc"][k],
                           _kc_dot(rows["t"][k]))
            assert_bits(self, tau, rows["tau"][k], f"tau at step {k}")

    def test_smc_is_its_formula(self):
        """The sliding-mode law recomputed in numpy from a run's measured
        states (BASELINES §2), independently of the Rust code."""
        k1, k2, ks, phi = 15.0, 15.0, 2.0, 0.05
        rows, _ = testbed.sim(law="smc", duration=3.0, set={"plant.sensor.q_noise_std": 1e-4})
        e = rows["q_measured"] - rows["q_d"]
        ed = rows["qd_measured"] - rows["qd_d"]
        s = ed + k1 * e
        tau = -k2 * s - ks * np.clip(s / phi, -1.0, 1.0)
        self.assertTrue(np.allclose(tau, rows["tau"], rtol=1e-12, atol=1e-12),
                        np.abs(tau - rows["tau"]).max())
        # Both of the law's regimes were exercised: the linear layer and the switch.
        inside = np.abs(s) < phi
        self.assertTrue(inside.any() and not inside.all())

    def test_cbf_ctc_is_its_formula(self):
        """The CBF–QP filter over computed torque recomputed in numpy
        (BASELINES §3) with the engine's M and h = C q̇ + G, on a run whose
        envelope is tight enough for the filter to act."""
        # A fast filter (λ = 60) against ctc's poles at −15: it binds
        # while the error, outside the envelope at T_c, comes back.
        kc, tc, lam = 0.05, 0.1, 60.0
        rows, _ = testbed.sim(law="cbf-ctc", duration=2.0, set={
            "controller.law": "cbf-ctc", "controller.tc": tc, "controller.cbf_rate": lam,
            "plant.saturate": False,
            "envelope.joints": [{"offset": kc}, {"offset": kc}]})
        robot = testbed.Robot()
        t = rows["t"]
        qdd_d = np.stack([-4.0 * np.sin(2.0 * t), -np.cos(t)], axis=1)  # scenarios/paper.toml
        kp, kd = 15.0 * 15.0, 15.0 + 15.0
        acted = 0
        for k in range(len(t)):
            q, qd = rows["q_measured"][k], rows["qd_measured"][k]
            e, ed = q - rows["q_d"][k], qd - rows["qd_d"][k]
            u = -kd * ed - kp * e
            if t[k] >= tc:
                h, hd = kc * kc - e * e, -2.0 * e * ed
                b = -2.0 * ed * ed + 2.0 * lam * hd + lam * lam * h
                with np.errstate(divide="ignore", invalid="ignore"):
                    bound = b / (2.0 * e)
                filtered = np.where(e > 0, np.minimum(u, bound), np.where(e < 0, np.maximum(u, bound), u))
                acted += int(np.any(filtered != u))
                u = filtered
            tau = robot.mass_matrix(q) @ (qdd_d[k] + u) + robot.bias(q, qd)
            self.assertTrue(np.allclose(tau, rows["tau"][k], rtol=1e-9, atol=1e-9),
                            (k, tau, rows["tau"][k]))
        self.assertGreater(acted, 0, "the filter acted on some step")

    def test_mpc_is_its_qp(self):
        """`mpc` (BASELINES §3) re-derived in numpy from a whole run: each
        joint's QP posed in the original variables and condensed (the law
        poses it scaled and sparse), solved exactly by active-set
        enumeration (the law uses clarabel's interior point), then
        τ = M (q̈_d + u₀) + C q̇ + G with the engine's M and h."""
        kc, tc, horizon, h = 0.02, 0.1, 4, 0.01
        rows, _ = testbed.sim(law="mpc", duration=1.5, set={
            "controller.law": "mpc", "controller.tc": tc, "controller.mpc_horizon": horizon,
            "plant.saturate": False,
            "envelope.joints": [{"offset": kc}, {"offset": kc}]})
        robot = testbed.Robot()
        t = rows["t"]
        qdd_d = np.stack([-4.0 * np.sin(2.0 * t), -np.cos(t)], axis=1)  # scenarios/paper.toml
        kp, kd = 15.0 * 15.0, 15.0 + 15.0
        qp = _CondensedMpc(kp, kd, h, horizon)
        active = 0
        for k in range(0, len(t), 3):
            q, qd = rows["q_measured"][k], rows["qd_measured"][k]
            e, ed = q - rows["q_d"][k], qd - rows["qd_d"][k]
            u = np.zeros(2)
            for i in range(2):
                bounds = [kc if t[k] + j * h >= tc else None for j in range(1, horizon + 1)]
                u[i], n_active = qp.solve(e[i], ed[i], bounds)
                active += n_active > 0
            tau = robot.mass_matrix(q) @ (qdd_d[k] + u) + robot.bias(q, qd)
            self.assertTrue(np.allclose(tau, rows["tau"][k], rtol=1e-4, atol=1e-4),
                            (k, tau, rows["tau"][k]))
        self.assertGreater(active, 10, "the envelope constrained some steps")

    def test_pd_is_its_formula(self):
        law = testbed.Law("pd", params={"k1": 4.0, "k2": 3.0})
        q, qd = np.array([0.2, -0.1]), np.array([0.5, 0.25])
        tau = law.step(0.0, q, qd, np.zeros(2), np.zeros(2), np.zeros(2), np.ones(2), np.zeros(2))
        self.assertTrue(np.allclose(tau, -4.0 * 3.0 * q - 3.0 * qd))
        self.assertEqual(law.params["k1"], 4.0)


class _CondensedMpc:
    """One joint's MPC QP of BASELINES §3 in the original variables:
    minimise ½ Σ_{j<N} x_jᵀ Q x_j h + ½ x_Nᵀ P x_N + ½ Σ u_k² h over
    u₀…u_{N−1}, x_j = A^j x₀ + Σ A^{j−1−k} B u_k, |e_j| ≤ k_j."""

    def __init__(self, kp, kd, h, horizon):
        self.h, self.n = h, horizon
        a = np.array([[1.0, h], [0.0, 1.0]])
        b = np.array([[0.5 * h * h], [h]])
        q = np.diag([kp * kp, max(kd * kd - 2.0 * kp, 0.0)]) * h
        r = np.array([[h]])
        p = q.copy()
        for _ in range(100000):  # the discrete Riccati equation
            gain = np.linalg.solve(r + b.T @ p @ b, b.T @ p @ a)
            nxt = q + a.T @ p @ a - a.T @ p @ b @ gain
            if np.max(np.abs(nxt - p)) <= 1e-14 * np.max(np.abs(nxt)):
                p = nxt
                break
            p = nxt
        phi = np.vstack([np.linalg.matrix_power(a, j) for j in range(1, horizon + 1)])
        gamma = np.zeros((2 * horizon, horizon))
        for j in range(1, horizon + 1):
            for k in range(j):
                gamma[2 * (j - 1):2 * j, k] = (np.linalg.matrix_power(a, j - 1 - k) @ b)[:, 0]
        qbar = np.zeros((2 * horizon, 2 * horizon))
        for j in range(1, horizon):
            qbar[2 * (j - 1):2 * j, 2 * (j - 1):2 * j] = q
        qbar[-2:, -2:] = p
        self.hess = gamma.T @ qbar @ gamma + h * np.eye(horizon)
        self.lin = gamma.T @ qbar @ phi
        self.pos, self.phi_e = gamma[0::2, :], phi[0::2, :]

    def solve(self, e, ed, bounds):
        """u₀ and the number of active constraints: the KKT point of the
        smallest active set that is feasible with multipliers ≥ 0 (unique:
        the QP is strictly convex)."""
        x0 = np.array([e, ed])
        f = self.lin @ x0
        rows, rhs = [], []
        for j, k in enumerate(bounds):
            if k is not None:
                free = self.phi_e[j] @ x0
                rows += [self.pos[j], -self.pos[j]]
                rhs += [k - free, k + free]
        g, w = np.array(rows).reshape(-1, self.n), np.array(rhs)
        for size in range(len(rhs) + 1):
            for subset in itertools.combinations(range(len(rhs)), size):
                ga = g[list(subset)]
                kkt = np.block([[self.hess, ga.T], [ga, np.zeros((size, size))]])
                try:
                    sol = np.linalg.solve(kkt, np.concatenate([-f, w[list(subset)]]))
                except np.linalg.LinAlgError:
                    continue
                u, lam = sol[:self.n], sol[self.n:]
                if np.all(lam >= -1e-9) and np.all(g @ u <= w + 1e-9):
                    return u[0], size
        raise AssertionError("no KKT point found")


class CtrlC(unittest.TestCase):
    def test_ctrl_c_stops_a_slow_sim_at_once(self):
        """#48 item 7 (N4): sim looked for Ctrl-C every 4096 steps, over a
        minute where a stiff spring makes a step 10 ms or more (8000
        substeps of the two-link arm). It looks every 50 ms of wall time:
        a SIGINT ends the run within seconds (a watchdog, not a timing)."""
        code = ("import testbed\n"
                "print('running', flush=True)\n"
                "testbed.sim(duration=60.0, set={'plant.actuator.stiffness': 1.28e6,"
                " 'plant.actuator.motor_inertia': 1e-6})\n")
        p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        try:
            self.assertEqual(p.stdout.readline().strip(), "running")
            # Inside the run by then: planning takes milliseconds.
            time.sleep(1.5)
            self.assertIsNone(p.poll(), "the 60 s run ended on its own")
            p.send_signal(signal.SIGINT)
            _, err = p.communicate(timeout=20)
        finally:
            p.kill()
            p.wait()
        self.assertIn("KeyboardInterrupt", err)


def _kc_dot(t):
    """k̇_c of the paper's envelope (scenarios/paper.toml)."""
    return np.array([0.1 * 0.5 * np.cos(0.5 * t), -0.1 * 0.5 * np.sin(0.5 * t)])


if __name__ == "__main__":
    unittest.main()
