"""`testbed.tune`: the search space from the parameter table, studies that
resume after kill -9 and that several processes share with every trial
recorded once, a refused mismatch, the best trial as a runnable scenario,
held-out evaluation."""

import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from collections import Counter
from pathlib import Path

import numpy as np

import testbed
from testbed import tune

# Short studies: 2 seeds of 0.3 s (T_c = 0.2 s) are a few milliseconds a trial.
QUICK = ["--scenario", "paper_randomised", "--seeds", "2", "--duration", "0.3",
         "--fixed", "controller.tc=0.2", "--no-progress", "--threads", "1"]

#: Watchdog of any wait below: the test fails, never hangs.
DEADLINE_S = 120.0


def tune_cmd(*args) -> list:
    return [sys.executable, "-m", "testbed.tune", *map(str, args)]


def trials(path: Path, name: str):
    study, _ = tune.open_study(path, name, None)
    return study.get_trials(deepcopy=False)


def states(ts) -> Counter:
    return Counter(t.state.name for t in ts)


def wait_for(what, cond):
    end = time.monotonic() + DEADLINE_S
    while not cond():
        if time.monotonic() > end:
            raise AssertionError(f"waited {DEADLINE_S} s for {what}")
        time.sleep(0.05)


class Space(unittest.TestCase):
    def test_each_laws_space_is_its_keys_with_ranges(self):
        keys = lambda law: [d["key"] for d in testbed.search_space(law)]
        self.assertEqual(keys("pd"), ["k1", "k2"])
        self.assertIn("sigma_a", keys("nac"))
        self.assertNotIn("sigma_a", keys("nac-no-networks"))
        self.assertNotIn("sigma_c", keys("nac-no-critic"))
        self.assertIn("mpc_horizon", keys("mpc"))
        for law in testbed.LAWS:
            for d in testbed.search_space(law):
                self.assertIn(d["range"]["kind"], ("float", "int", "scale", "choice"), d)
        with self.assertRaises(testbed.TestbedError):
            testbed.search_space("nope")

    def test_the_cli_prints_the_same_space(self):
        from helpers import run_testbed

        out = run_testbed("tune", "--print-space", "mpc").stdout
        for d in testbed.search_space("mpc"):
            self.assertIn(d["key"], out)


class Studies(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)

    def tearDown(self):
        self.tmp.cleanup()

    def run_tune(self, *args, check=True):
        out = subprocess.run(tune_cmd(*args), capture_output=True, text=True, timeout=DEADLINE_S,
                             cwd=self.dir)
        if check and out.returncode != 0:
            raise AssertionError(f"tune {args} failed ({out.returncode}):\n{out.stderr}")
        return out

    def assert_every_trial_once(self, path, name, budget):
        ts = trials(path, name)
        s = states(ts)
        self.assertEqual(s["RUNNING"], 0, s)
        self.assertEqual(s["COMPLETE"] + s["PRUNED"], budget, s)
        # A trial failed by a dead process is tried again exactly once, with
        # the parameters it had drawn (it may have drawn only some).
        for f in (t for t in ts if t.state.name == "FAIL"):
            retries = [t for t in ts if t.user_attrs.get("retry_of") == f.number]
            self.assertEqual(len(retries), 1, f.number)
            for k, v in f.params.items():
                self.assertEqual(retries[0].params[k], v, k)
        self.assertEqual(len({t.number for t in ts}), len(ts))

    def test_a_trial_left_running_by_a_dead_process_is_run_again_once(self):
        path, name = self.dir / "s.journal", "dead"
        self.run_tune("run", "--law", "pd", *QUICK, "--trials", "4", "--storage", path,
                      "--study", name)
        # A worker that asks for a trial, draws its parameters and dies.
        code = (
            "import os, sys, socket, time\n"
            "from pathlib import Path\n"
            "from testbed import tune\n"
            f"study, _ = tune.open_study(Path({str(path)!r}), {name!r}, None)\n"
            "t = study.ask()\n"
            "t.suggest_float('k1_scale', 0.0625, 4.0, log=True)\n"
            "study._storage.set_trial_system_attr(t._trial_id, 'tune_worker', "
            "{'host': socket.gethostname(), 'pid': os.getpid(), 'started': time.time()})\n"
            "os.kill(os.getpid(), 9)\n"
        )
        dead = subprocess.run([sys.executable, "-c", code], timeout=DEADLINE_S)
        self.assertEqual(dead.returncode, -signal.SIGKILL)
        self.assertEqual(states(trials(path, name))["RUNNING"], 1)
        out = self.run_tune("run", "--law", "pd", *QUICK, "--trials", "8", "--storage", path,
                            "--study", name)
        self.assertIn("1 trial(s) whose process died are run again", out.stderr)
        self.assertEqual(states(trials(path, name))["FAIL"], 1)
        self.assert_every_trial_once(path, name, 8)

    def test_kill_9_mid_study_then_resume_records_every_trial_once(self):
        path, name = self.dir / "k.journal", "killed"
        args = ["run", "--law", "nac", *QUICK, "--trials", "40", "--storage", path, "--study", name]
        p = subprocess.Popen(tune_cmd(*args), cwd=self.dir, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
        try:
            wait_for("5 finished trials",
                     lambda: path.exists() and sum(
                         t.state.name in ("COMPLETE", "PRUNED") for t in trials(path, name)) >= 5)
        finally:
            p.kill()
            p.wait(timeout=DEADLINE_S)
        self.assertLess(sum(t.state.name != "RUNNING" for t in trials(path, name)), 40)
        self.run_tune(*args)
        self.assert_every_trial_once(path, name, 40)

    def test_two_processes_share_one_study_and_record_every_trial_once(self):
        path, name = self.dir / "two.journal", "shared"
        args = ["run", "--law", "pd", *QUICK, "--trials", "30", "--storage", path, "--study", name]
        ps = [subprocess.Popen(tune_cmd(*args), cwd=self.dir, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True) for _ in range(2)]
        ran = []
        for p in ps:
            out, err = p.communicate(timeout=DEADLINE_S)
            self.assertEqual(p.returncode, 0, err)
            ran.append(int(out.split("ran ")[1].split(" ")[0]))
        self.assertEqual(sum(ran), 30, ran)
        self.assertTrue(all(r > 0 for r in ran), ran)  # both took part
        self.assert_every_trial_once(path, name, 30)

    def test_a_resumed_study_must_be_the_same_search(self):
        path = self.dir / "m.journal"
        self.run_tune("run", "--law", "pd", *QUICK, "--trials", "2", "--storage", path, "--study", "m")
        bad = [a if a != "2" else "3" for a in QUICK]  # --seeds 3
        out = self.run_tune("run", "--law", "pd", *bad, "--trials", "2", "--storage", path,
                            "--study", "m", check=False)
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("seeds = 2", out.stderr)

    def test_the_same_sampler_seed_finds_the_same_best(self):
        bests = []
        for i in range(2):
            path = self.dir / f"d{i}.journal"
            self.run_tune("run", "--law", "pd", *QUICK, "--trials", "15", "--storage", path,
                          "--study", "d")
            bests.append(tune.summary(path, "d")["best"])
        self.assertEqual(bests[0]["params"], bests[1]["params"])
        self.assertEqual(bests[0]["value"], bests[1]["value"])

    def test_the_best_trial_is_a_scenario_file_that_runs_as_it_is(self):
        path = self.dir / "b.journal"
        self.run_tune("run", "--law", "pd", *QUICK, "--trials", "6", "--storage", path, "--study", "b")
        f = self.dir / "best.toml"
        self.run_tune("best", path, "--write-scenario", f)
        best = tune.summary(path, "b")["best"]
        # The file holds the best gains, and runs as the study's trial did.
        r = testbed.compare(str(f), laws=["pd"], seeds=2,
                            set={"seed": 1000, "duration_s": 0.3})
        vals, _ = tune.per_seed(r, "pd")
        self.assertAlmostEqual(float(np.median(vals)), best["value"], places=12)
        self.assertIn("k1 =", f.read_text())

    def test_held_out_seeds_may_not_overlap_the_training_seeds(self):
        path = self.dir / "h.journal"
        self.run_tune("run", "--law", "pd", *QUICK, "--trials", "3", "--storage", path, "--study", "h")
        out = self.run_tune("evaluate", path, "--first-seed", "1001", "--seeds", "3", check=False)
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("overlap", out.stderr)
        out = self.run_tune("evaluate", path, "--first-seed", "5000", "--seeds", "4",
                            "--duration", "0.3", "--also", "nac")
        self.assertIn("pd ", out.stdout)
        self.assertIn("nac ", out.stdout)


class Statistics(unittest.TestCase):
    def test_a_comparison_row_carries_the_iqm_and_its_interval(self):
        r = testbed.compare("paper_randomised", laws=["pd"], seeds=8,
                            set={"seed": 1000, "duration_s": 0.5, "controller.tc": 0.2})
        row = r["laws"][0]
        x = np.sort([run["summary"]["metrics"]["iae_after_tc"] for run in row["runs"]])
        self.assertAlmostEqual(row["iqm"]["iae"], float(np.mean(x[2:6])), places=12)
        self.assertLess(row["iqm_ci95_low"]["iae"], row["iqm"]["iae"])
        self.assertGreater(row["iqm_ci95_high"]["iae"], row["iqm"]["iae"])


if __name__ == "__main__":
    unittest.main()
