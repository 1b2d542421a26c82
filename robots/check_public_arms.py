#!/usr/bin/env python3
"""Runs `testbed sim --robot FILE --json` (each URDF's default scenario) on
every URDF below a folder and prints one line each: clean, left the
envelope, refused (with the message), or timed out.

    pip download example-robot-data==6.0.0 --no-deps -d /tmp/erd
    (cd /tmp/erd && unzip -q example_robot_data-*.whl)
    python3 robots/check_public_arms.py /tmp/erd --testbed target/release/testbed

docs/results.md quotes its output for example-robot-data 6.0.0.
"""

import argparse
import json
import subprocess
from pathlib import Path


def check(testbed: str, urdf: Path, timeout: float) -> str:
    try:
        p = subprocess.run(
            [testbed, "sim", "--robot", str(urdf), "--json"],
            capture_output=True, text=True, timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return "TIMEOUT"
    if "panicked" in p.stderr:
        return "PANIC " + p.stderr[-300:]
    if p.returncode != 0 or not p.stdout.strip():
        last = p.stderr.strip().splitlines()[-1:] or [""]
        return f"refused({p.returncode}) {last[0][:220]}"
    s = json.loads(p.stdout)
    ok = s["constraint_satisfied_after_tc"] and s["finite"]
    return (
        f"{'ok' if ok else 'LEFT'} dof {s['dof']} breaches {s['barrier_breached_steps']} "
        f"rt {s['realtime_factor']:.1f}x"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", type=Path)
    ap.add_argument("--testbed", default="target/release/testbed")
    ap.add_argument("--timeout", type=float, default=120.0)
    args = ap.parse_args()
    # `.URDF` too: Robotiq's grippers ship that way.
    urdfs = (p for p in args.folder.rglob("*") if p.suffix.lower() == ".urdf" and p.is_file())
    for urdf in sorted(urdfs):
        print(f"{urdf.relative_to(args.folder)} | {check(args.testbed, urdf, args.timeout)}", flush=True)


if __name__ == "__main__":
    try:
        main()
    except BrokenPipeError:  # `… | head`: the reader has what it wanted
        raise SystemExit(141)
