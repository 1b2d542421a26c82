#!/usr/bin/env bash
# Writes the golden log of today's log format: the paper scenario, 0.2 s in
# lockstep (200 steps), as tests/golden/paper_lockstep_format<N>.mcap, where
# N is the format the logger writes (logger::LOG_FORMAT). Older formats' logs
# are kept as they were written: they are what old runs left on disk.
#   cargo build --release && bash tests/golden/regenerate.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
testbed=${TESTBED:-target/release/testbed}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
log=$("$testbed" run --mode lockstep --duration 0.2 --json --runs-dir "$tmp" \
    | python3 -c 'import json, sys; print(json.load(sys.stdin)["log"])')
format=$(grep -o 'pub const LOG_FORMAT: u32 = [0-9]*' logger/src/writer.rs | grep -o '[0-9]*$')
cp "$log" "tests/golden/paper_lockstep_format${format}.mcap"
echo "wrote tests/golden/paper_lockstep_format${format}.mcap"
