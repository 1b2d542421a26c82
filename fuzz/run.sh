#!/usr/bin/env bash
# Runs every cargo-fuzz target for a bounded time (default 60 s each):
#   bash fuzz/run.sh [SECONDS]
# FUZZ_DEV=1 builds without optimisation: about 3 times quicker to build
# (CI), slower to run.
# Seeds are fuzz/seeds/<target>; new inputs go to a scratch corpus. A crash
# stops the run non-zero and leaves its input in fuzz/artifacts/<target>/
# (keep it as a regression test, see fuzz/README.md).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
# cargo-fuzz passes -Z sanitizer flags; this lets the one stable toolchain
# of this machine accept them (no nightly can be installed here).
export RUSTC_BOOTSTRAP=1
# Build every target first, so a failing build says so (not "crashed").
if ! cargo fuzz build ${FUZZ_DEV:+--dev} --fuzz-dir fuzz; then
    echo "fuzz: the targets did not build (see above; no fuzzing ran)" >&2
    exit 1
fi
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
for target in scenario urdf mjcf mjcf_include log sweep node_config; do
    mkdir -p "$scratch/$target" "$scratch/tmp"
    status=0
    # TMPDIR in the scratch folder: the scratch file systems a target
    # builds (mjcf_include's model folders) go when the run ends.
    TMPDIR="$scratch/tmp" cargo fuzz run ${FUZZ_DEV:+--dev} --fuzz-dir fuzz "$target" "$scratch/$target" "fuzz/seeds/$target" -- \
        -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
        >"$scratch/$target.log" 2>&1 || status=$?
    # libFuzzer's progress lines stay in the log; the outcome is shown.
    grep -E "^(Done|stat::number_of_executed_units|==[0-9]+==|SUMMARY|.*panicked|.*Test unit written|error)" \
        "$scratch/$target.log" || true
    if [ "$status" -ne 0 ]; then
        tail -40 "$scratch/$target.log" >&2
        echo "fuzz: target $target failed (status $status); its input is in fuzz/artifacts/$target/" >&2
        exit 1
    fi
    echo "fuzz: $target ran clean for ${seconds} s"
done
