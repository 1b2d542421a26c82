"""What the in-process module's tests share: the testbed binary to compare
with, and CSV reading."""

import csv
import json
import os
import subprocess
import unittest
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]


def testbed_bin() -> str:
    """The `testbed` binary: TESTBED_BIN (the system test sets it), else a
    release build in target/."""
    path = os.environ.get("TESTBED_BIN") or str(ROOT / "target/release/testbed")
    if not Path(path).exists():
        raise unittest.SkipTest("no testbed binary: set TESTBED_BIN or cargo build --release")
    return path


def run_testbed(*args, cwd=ROOT) -> subprocess.CompletedProcess:
    out = subprocess.run([testbed_bin(), *map(str, args)], cwd=cwd, capture_output=True,
                         text=True, timeout=600)
    if out.returncode != 0:
        raise AssertionError(f"testbed {' '.join(map(str, args))} failed ({out.returncode}):\n{out.stderr}")
    return out


def cli_sim(tmp: Path, *args) -> tuple:
    """`testbed sim ARGS --csv --json`: (columns by CSV name, summary)."""
    csv_path = tmp / "sim.csv"
    out = run_testbed("sim", *args, "--json", "--csv", csv_path)
    with open(csv_path, newline="") as f:
        rows = list(csv.reader(f))
    head, body = rows[0], rows[1:]
    # The CSV prints each f64 as the shortest text that parses back to it.
    cols = {h: np.array([float(r[i]) for r in body]) for i, h in enumerate(head)}
    return cols, json.loads(out.stdout)


def joint(cols: dict, stem: str, n: int) -> np.ndarray:
    return np.stack([cols[f"{stem}{i}"] for i in range(n)], axis=1)


def assert_bits(test: unittest.TestCase, a, b, what: str) -> None:
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    test.assertEqual(a.shape, b.shape, what)
    same = (a.view(np.uint64) == b.view(np.uint64)) | (a == b)
    if not same.all():
        i = np.argwhere(~same)[0]
        test.fail(f"{what}: first difference at {tuple(i)}: {a[tuple(i)]!r} against {b[tuple(i)]!r}")
