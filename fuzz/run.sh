#!/usr/bin/env bash
# Runs one fuzz target under AFL++ until it has made EXECS executions (default 1,000,000) or
# SECONDS_CAP seconds have passed (default 1800), at the lowest CPU priority, then prints
# the campaign's figures (the row of FUZZING.md).
#
#   fuzz/run.sh <target> [execs] [seconds]
#
# Build first: (cd fuzz && cargo afl build --release). Findings are kept in
# $FUZZ_OUT/<target> (default /tmp/wscg-fuzz-out): crashes/ and hangs/ hold the inputs.
set -euo pipefail
cd "$(dirname "$0")"
target=$1
execs=${2:-1000000}
cap=${3:-1800}
bin=${CARGO_TARGET_DIR:-target}/release/wscg-fuzz
out=${FUZZ_OUT:-/tmp/wscg-fuzz-out}/$target
rm -rf "$out"
mkdir -p "$(dirname "$out")"
AFL_SKIP_CPUFREQ=1 AFL_NO_AFFINITY=1 AFL_NO_UI=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 \
  nice -n 19 cargo afl fuzz -i "corpus/$target" -o "$out" -E "$execs" -V "$cap" -t 2000 \
  -- "$bin" "$target" >"$out.log" 2>&1 || true
stats=$out/default/fuzzer_stats
get() { awk -F' *: *' -v k="$1" '$1 == k { print $2 }' "$stats"; }
echo "$target execs=$(get execs_done) time_s=$(get run_time) execs_per_s=$(get execs_per_sec)" \
  "corpus=$(get corpus_count) crashes=$(get saved_crashes) hangs=$(get saved_hangs)" \
  "edges=$(get edges_found)/$(get total_edges)"
