#!/usr/bin/env bash
# Makes, once, the training environment: a virtual environment with torch,
# Stable-Baselines3, Gymnasium 1.4.0 and onnx, in which `import testbed`
# finds this checkout's module (python/inprocess, built by build-module.sh,
# through a .pth file), and prints its python. A no-op when it is there.
#   bash python/setup-train-venv.sh [DIR]
#   (default: $TESTBED_SB3_VENV, else ~/.cache/sb3-venv: outside target/,
#   so `cargo clean` keeps its gigabytes of torch)
# torch comes from PyTorch's CPU index (a fraction of the CUDA wheels'
# size; TORCH_INDEX_URL picks another), falling back to PyPI. PYTHON picks
# the interpreter; it must be the version the module is built for (that of
# target/python-venv, 3.11 in CI). Safe to run from several processes at
# once: the first installs, the others wait.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="${1:-${TESTBED_SB3_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/sb3-venv}}"
py="${PYTHON:-python3}"
mkdir -p "$(dirname "$dir")"
exec 9>"$dir.lock"
flock 9
ready() {
    "$dir/bin/python" - <<'EOF' 2>/dev/null
import gymnasium, onnx, stable_baselines3, torch
assert gymnasium.__version__ == "1.4.0", gymnasium.__version__
EOF
}
if ! ready; then
    echo "setup-train-venv: making $dir (torch, stable-baselines3, gymnasium 1.4.0, onnx); this takes minutes" >&2
    [ -x "$dir/bin/python" ] || "$py" -m venv "$dir" >&2 || {
        echo "setup-train-venv: $py cannot make a virtual environment (install python3-venv)" >&2
        exit 1
    }
    pip=("$dir/bin/python" -m pip install --quiet --disable-pip-version-check)
    "${pip[@]}" --index-url "${TORCH_INDEX_URL:-https://download.pytorch.org/whl/cpu}" torch >&2 ||
        "${pip[@]}" torch >&2 || {
        echo "setup-train-venv: cannot install torch into $dir" >&2
        exit 1
    }
    "${pip[@]}" "stable-baselines3>=2.3" "gymnasium==1.4.0" "onnx>=1.16,<2" "numpy>=1.24" >&2 || {
        echo "setup-train-venv: cannot install stable-baselines3, gymnasium and onnx into $dir" >&2
        exit 1
    }
    ready || { echo "setup-train-venv: $dir still cannot import torch, stable_baselines3, gymnasium 1.4.0 and onnx" >&2; exit 1; }
fi
# The checkout's module, importable as `testbed` (kept current: the
# checkout may have moved).
site="$("$dir/bin/python" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")"
echo "$root/python/inprocess" >"$site/testbed-checkout.pth"
echo "$dir/bin/python"
