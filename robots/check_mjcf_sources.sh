#!/usr/bin/env bash
# Every MJCF model in five PyPI packages (robosuite, dm_control, Gymnasium,
# Gymnasium-Robotics, Meta-World), through the testbed twice:
#   1. each model's default scenario (robots/check_public_arms.py), and
#   2. the dynamics of every model that ran, against MuJoCo's own
#      (arm-model/tests/mujoco.rs through TESTBED_MJCF_ARMS), leaving out
#      the files MuJoCo itself refuses.
# docs/results.md ("MJCF arms") quotes the output.
#
#   bash robots/check_mjcf_sources.sh [WORKDIR]   # default /tmp/mjcf-sources
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-/tmp/mjcf-sources}
mkdir -p "$work/x"
for p in robosuite==1.5.2 dm_control==1.0.52 gymnasium==1.4.0 gymnasium-robotics==1.4.2 metaworld==3.1.1; do
    name=${p%%==*}
    if [ ! -d "$work/x/$name" ]; then
        pip download --no-deps -q "$p" -d "$work/wheels"
        mkdir -p "$work/x/$name"
        unzip -q -o "$work"/wheels/"$(echo "${name}" | tr - _)"-*.whl -d "$work/x/$name"
    fi
done
cd "$root"
cargo build --release -q -p launch
python3 robots/check_public_arms.py "$work/x" --timeout 120 | tee "$work/runs.txt"
python=$(bash python/setup-mujoco-venv.sh)
# The MJCF files that ran, less those MuJoCo refuses (a repeated mesh
# name, an unknown attribute): those compare with nothing.
arms=$(grep ' | ok ' "$work/runs.txt" | cut -d' ' -f1 | grep '\.xml$' | sed "s#^#$work/x/#" |
    "$python" -c '
import sys
sys.path.insert(0, "arm-model/tests")
import mujoco_dynamics as md
ok = []
for f in sys.stdin.read().split():
    try:
        md.without_meshes(f)
        ok.append(f)
    except Exception as e:
        print(f"MuJoCo refuses {f}: {str(e).splitlines()[0]}", file=sys.stderr)
print(":".join(ok))
')
TESTBED_MJCF_ARMS="$arms" cargo test --release -q -p arm-model --test mujoco -- --nocapture 2>&1 |
    grep -E 'largest|differs|test result'
