#!/usr/bin/env bash
# Builds the in-process module `testbed` (python/inprocess: the Rust core
# with PyO3, by maturin) into the Python environment of setup-venv.sh, with
# Gymnasium, and prints that environment's python.
#   bash python/build-module.sh [--release] [DIR]   (default: target/python-venv)
# Without --release the module is built in cargo's dev profile (the
# workspace's: dependencies optimised, the testbed's crates lightly), which
# reuses the test build; --release for benchmarks. Safe to run from several
# processes at once: the first builds, the others wait for it.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
release=""
if [ "${1:-}" = "--release" ]; then release="--release"; shift; fi
python="$(bash "$root/python/setup-venv.sh" "$@")"
venv="$(dirname "$(dirname "$python")")"
exec 8>"$venv.module.lock"
flock 8
# onnx: testbed.onnx_export writes policies for the Rust node (its tests);
# optuna and tqdm: testbed.tune (`testbed tune`, the wheel's `tune` extra).
if ! "$python" -c "import gymnasium, maturin, onnx, optuna, tqdm" 2>/dev/null; then
    "$python" -m pip install --quiet --disable-pip-version-check \
        "maturin>=1.9,<2" "gymnasium==1.4.0" "onnx>=1.16,<2" "optuna>=4,<6" "tqdm>=4" >&2
fi
# maturin finds the environment through VIRTUAL_ENV; cargo's own output
# goes to stderr, so stdout carries only the python's path.
(cd "$root/python/inprocess" &&
    VIRTUAL_ENV="$venv" "$venv/bin/maturin" develop --quiet $release >&2) || {
    echo "build-module: maturin could not build python/inprocess into $venv" >&2
    exit 1
}
"$python" -c "import testbed" || { echo "build-module: $venv cannot import testbed" >&2; exit 1; }
echo "$python"
