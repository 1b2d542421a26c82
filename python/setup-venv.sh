#!/usr/bin/env bash
# Creates (once) a Python virtual environment with the testbed_controller
# package (editable) and what it needs: the iceoryx2 wheel, numpy, and the
# official MCAP readers (mcap, mcap-ros2-support) for its log reader; with
# --peer also MuJoCo, for the Python + MuJoCo loop of `testbed bench --peer`.
#   bash python/setup-venv.sh [--peer] [DIR]     (default: target/python-venv)
# Prints the environment's python on success. Safe to run from several
# processes at once (the test suite does): the first one installs, the
# others wait for it.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
peer=""
if [ "${1:-}" = "--peer" ]; then peer=1; shift; fi
venv="${1:-$root/target/python-venv}"
python="${PYTHON:-python3}"
mkdir -p "$(dirname "$venv")"
exec 9>"$venv.lock"
flock 9
# Ready: everything imports, and the package is this checkout's (a venv
# copied from another worktree would import that one's).
ready() {
    [ -x "$venv/bin/python3" ] && "$venv/bin/python3" -c "
import os, sys, testbed_controller, iceoryx2, numpy, mcap, mcap_ros2
here = os.path.realpath(os.path.dirname(testbed_controller.__file__))
sys.exit(here != os.path.realpath('$root/python/testbed_controller'))" 2>/dev/null
}
if ! ready; then
    rm -rf "$venv"
    "$python" -m venv "$venv" >&2
    "$venv/bin/python3" -m pip install --quiet --disable-pip-version-check -e "$root/python" >&2
    ready || { echo "setup-venv: $venv was made but cannot import testbed_controller" >&2; exit 1; }
fi
if [ -n "$peer" ] && ! "$venv/bin/python3" -c "import mujoco, imageio, packaging" 2>/dev/null; then
    "$venv/bin/python3" -m pip install --quiet --disable-pip-version-check -e "$root/python[peer]" >&2
    "$venv/bin/python3" -c "import mujoco" || { echo "setup-venv: MuJoCo did not install in $venv" >&2; exit 1; }
fi
echo "$venv/bin/python3"
