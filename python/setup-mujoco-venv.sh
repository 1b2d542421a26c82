#!/usr/bin/env bash
# Makes, once, the environment in which arm-model's MuJoCo comparison
# (arm-model/tests/mujoco.rs) runs MuJoCo itself: a virtual environment
# with the `mujoco` wheel (a few tens of MB) and numpy; prints its python.
# A no-op when it is there.
#   bash python/setup-mujoco-venv.sh [DIR]
#   (default: $TESTBED_MUJOCO_VENV, else ~/.cache/mujoco-venv: outside
#   target/, so `cargo clean` keeps it)
# PYTHON picks the interpreter. Safe to run from several processes at
# once: the first installs, the others wait.
set -euo pipefail
dir="${1:-${TESTBED_MUJOCO_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/mujoco-venv}}"
py="${PYTHON:-python3}"
mkdir -p "$(dirname "$dir")"
exec 9>"$dir.lock"
flock 9
# The version the comparison was written against: MuJoCo's compiler rules
# (inertia from geoms, armature) are stable, but a pin keeps CI's answer
# the developer's.
want="4.0.1"
ready() {
    "$dir/bin/python" - "$want" <<'PY' 2>/dev/null
import sys, mujoco, numpy
assert mujoco.__version__ == sys.argv[1], mujoco.__version__
PY
}
if ! ready; then
    echo "setup-mujoco-venv: making $dir (mujoco $want, numpy)" >&2
    [ -x "$dir/bin/python" ] || "$py" -m venv "$dir" >&2 || {
        echo "setup-mujoco-venv: $py cannot make a virtual environment (install python3-venv)" >&2
        exit 1
    }
    "$dir/bin/python" -m pip install --quiet --disable-pip-version-check "mujoco==$want" "numpy>=1.24" >&2 || {
        echo "setup-mujoco-venv: cannot install mujoco $want into $dir" >&2
        exit 1
    }
    ready || {
        echo "setup-mujoco-venv: mujoco $want does not import in $dir" >&2
        exit 1
    }
fi
echo "$dir/bin/python"
