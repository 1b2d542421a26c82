#!/usr/bin/env python3
"""Says whether the Python module's build and the workspace's test build
compile their shared dependencies once.

Cargo compiles a dependency again when the features it is built with
differ, and so every crate above it: the module (maturin, built first in
.ci/run) unifies features over its own graph, the test build over the whole
workspace with dev-dependencies. When they differ, CI compiles most of the
graph twice (20 minutes here, #62 item 4). python/inprocess/Cargo.toml pins
the features; this script compares the two unit graphs and names any
dependency whose features differ, with the pin that would fix it.

The unit graph is a nightly-only cargo output (RUSTC_BOOTSTRAP=1 on the
stable toolchain). When cargo cannot print it, the script says so and
passes: the check guards build time, not correctness.
    python3 .ci/shared-build.py
"""
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ENV = dict(os.environ, RUSTC_BOOTSTRAP="1")
UNIT_GRAPH = ["--offline", "--unit-graph", "-Z", "unstable-options"]


def host():
    """This machine's target triple: named, it makes cargo tell a build
    for build scripts and macros (no platform) from one for the code."""
    out = subprocess.run(["rustc", "-vV"], capture_output=True, text=True, check=True).stdout
    return next(line.split()[1] for line in out.splitlines() if line.startswith("host:"))


def unit_graph(args, cwd):
    out = subprocess.run(["cargo", *args, "--target", host(), *UNIT_GRAPH], cwd=cwd, env=ENV,
                         capture_output=True, text=True)
    if out.returncode != 0:
        print(f"shared-build: cargo cannot print its unit graph here ({out.stderr.strip()[-300:]}); not checked")
        sys.exit(0)
    return json.loads(out.stdout)


def units(graph):
    """The registry dependencies' builds, each as (package, target, kind,
    features, platform): a package built for build scripts and for the
    code is two of them. The workspace's own crates are built apart anyway."""
    return {
        (unit["pkg_id"].split("#")[-1], unit["target"]["name"],
         tuple(unit["target"]["kind"]), tuple(sorted(unit["features"])), unit["platform"])
        for unit in graph["units"]
        if unit["mode"] == "build" and not unit["pkg_id"].startswith("path+")
    }


def main():
    module = units(unit_graph(
        ["build", "-p", "testbed-python", "--lib", "--features", "pyo3/extension-module"],
        ROOT / "python" / "inprocess"))
    tests = units(unit_graph(["test", "--workspace", "--no-run"], ROOT))
    tested = {unit[0] for unit in tests}
    drift = sorted(unit for unit in module - tests if unit[0] in tested)
    for package, target, _, built, platform in drift:
        wanted = sorted(u[3] for u in tests if u[0] == package and u[1] == target and u[4] == platform)
        role = "the code" if platform else "build scripts and macros"
        print(f"shared-build: {package} ({target}, for {role}) is built for the module with {list(built)}, "
              f"for the tests with {[list(w) for w in wanted]}: pin the tests' features in "
              "python/inprocess/Cargo.toml")
    if drift:
        sys.exit(1)
    shared = sum(1 for unit in module if unit[0] in tested)
    print(f"shared-build: the module and the tests share all {shared} dependency builds they have in common")


if __name__ == "__main__":
    main()
