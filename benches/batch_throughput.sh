#!/usr/bin/env bash
# Throughput of `acmw batch`: N simulated 5-minute, 50 Hz, 13-IMU trials
# (20 distinct ones, seeds 1000-1019, every third with heading drift on the
# left calf, every fifth with sensor slippage of the right forearm, copied
# to make N), corrected with drift-centroid on
# 2 workers, reading and writing included. Prints trials per minute, then
# runs the batch again to time a resume that has nothing left to do.
#
#   benches/batch_throughput.sh [N=100] [ACMW_BINARY]
#
# ACMW_BINARY defaults to the release build under $CARGO_TARGET_DIR (or
# target/). Nothing in the project runs this script; `cargo test` does not
# need it (tests/batch.rs tests the batch itself).
set -euo pipefail
n=${1:-100}
acmw=${2:-${CARGO_TARGET_DIR:-$(dirname "$0")/../target}/release/acmw}
[ -x "$acmw" ] || { echo "no acmw binary at $acmw (cargo build --release)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/trials" "$work/distinct"
# 20 distinct trials, each copied under N/20 names (the batch does not know
# they repeat: every copy is read, corrected and written).
distinct=$(( n < 20 ? n : 20 ))
for ((k = 0; k < distinct; k++)); do
  extra=()
  ((k % 3 == 0)) && extra+=(--drift l_calf:30:0.05)
  ((k % 5 == 0)) && extra+=(--slip r_forearm:60:0.02:0:0:1)
  "$acmw" simulate full-body --duration 300 --seed $((1000 + k)) --truth-json-only \
    "${extra[@]}" -o "$work/distinct/d$k.csv.gz" >/dev/null
done
for ((k = 0; k < n; k++)); do
  cp "$work/distinct/d$((k % distinct)).csv.gz" "$work/trials/t$(printf %04d "$k").csv.gz"
done
now() { date +%s.%N; }
t0=$(now)
"$acmw" batch "$work/trials" --out "$work/out" --jobs 2 --quiet || true
t1=$(now)
"$acmw" batch "$work/trials" --out "$work/out" --jobs 2 --quiet || true
t2=$(now)
ok=$(grep -c ',ok,' "$work/out/manifest.csv" || true)
awk -v a="$t0" -v b="$t1" -v c="$t2" -v n="$n" -v ok="$ok" -v load="$(cut -d' ' -f1-3 /proc/loadavg)" 'BEGIN {
  printf "%d trials (%d ok) of 5 min on 2 workers: %.1f s, %.1f trials/min\n", n, ok, b - a, 60 * n / (b - a);
  printf "re-run with everything done: %.2f s\n", c - b;
  printf "load average while measured: %s\n", load;
}'
