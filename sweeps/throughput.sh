#!/usr/bin/env bash
# Sweep throughput on all cores against one: N interleaved pairs of the same
# 32-run sweep (--threads 1, then --threads <cores>), each into a fresh
# folder; prints each pair and the median of the pairs' ratios (pairs taken
# minutes apart on a shared machine disagree; a pair's two halves less so).
#   bash sweeps/throughput.sh [PAIRS]   (after cargo build --release)
set -euo pipefail
cd "$(dirname "$0")/.."
pairs=${1:-9}
cores=$(nproc)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/sweep.toml" <<'TOML'
seeds = 8
[set]
duration_s = 5.0
"plant.sensor.q_noise_std" = 0.001
[[axis]]
key = "controller.k1"
values = [10.0, 20.0]
[[axis]]
key = "controller.k2"
values = [10.0, 15.0]
TOML
for i in $(seq "$pairs"); do
    line=""
    for t in 1 "$cores"; do
        rm -rf "$tmp/out"
        s=$(date +%s.%N)
        target/release/testbed sweep run "$tmp/sweep.toml" --out "$tmp/out" --threads "$t" --no-progress 2>/dev/null
        e=$(date +%s.%N)
        line="$line $(echo "$e - $s" | bc)"
    done
    echo "$line"
done | awk -v c="$cores" '{printf "1 thread %.3f s, %d threads %.3f s, ratio %.3f\n", $1, c, $2, $1/$2; print $1/$2 > "/dev/stderr"}' \
    2> "$tmp/ratios"
sort -n "$tmp/ratios" | awk '{r[NR]=$1} END {printf "median ratio of %d pairs: %.3f\n", NR, r[int((NR+1)/2)]}'
