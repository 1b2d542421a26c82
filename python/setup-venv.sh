#!/usr/bin/env bash
# Creates (once) a Python virtual environment with the testbed_controller
# package (editable) and what it needs: the iceoryx2 wheel and numpy.
#   bash python/setup-venv.sh [DIR]     (default: target/python-venv)
# Prints the environment's python on success. Safe to run from several
# processes at once (the test suite does): the first one installs, the
# others wait for it.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
venv="${1:-$root/target/python-venv}"
python="${PYTHON:-python3}"
mkdir -p "$(dirname "$venv")"
exec 9>"$venv.lock"
flock 9
ready() { [ -x "$venv/bin/python3" ] && "$venv/bin/python3" -c "import testbed_controller, iceoryx2, numpy" 2>/dev/null; }
if ! ready; then
    rm -rf "$venv"
    "$python" -m venv "$venv" >&2
    "$venv/bin/python3" -m pip install --quiet --disable-pip-version-check -e "$root/python" >&2
    ready || { echo "setup-venv: $venv was made but cannot import testbed_controller" >&2; exit 1; }
fi
echo "$venv/bin/python3"
