#!/usr/bin/env bash
# Times `acmw correct` (reading and writing included) against an independent
# Python implementation of the method on the same 5-minute, 50 Hz, 13-IMU
# trial (drift + centroid), side by side in one run, and prints the ratio.
#
#   benches/cli_vs_reference.sh PATH/TO/acm_ref.py [ACMW_BINARY [BASELINE_BINARY]]
#
# The reference needs python3 with numpy and scipy. ACMW_BINARY defaults to
# the release build under $CARGO_TARGET_DIR (or target/). BASELINE_BINARY, when
# given (an older build of acmw), is timed in the same run, alternating with
# ACMW_BINARY, and must write the same bytes. Each acmw is run RUNS times
# (default 5) and its median is reported; the reference runs once. Nothing in
# the project runs this script; `cargo test` does not need it.
set -euo pipefail
if [ $# -lt 1 ]; then
  echo "usage: $0 PATH/TO/acm_ref.py [ACMW_BINARY [BASELINE_BINARY]]" >&2
  exit 2
fi
ref=$1
acmw=${2:-${CARGO_TARGET_DIR:-$(dirname "$0")/../target}/release/acmw}
base=${3:-}
runs=${RUNS:-5}
[ -f "$ref" ] || { echo "no reference at $ref" >&2; exit 2; }
[ -x "$acmw" ] || { echo "no acmw binary at $acmw (cargo build --release)" >&2; exit 2; }
[ -z "$base" ] || [ -x "$base" ] || { echo "no baseline binary at $base" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$acmw" simulate full-body --duration 300 --seed 5 -o "$work/trial.csv" >/dev/null

now() { date +%s.%N; }
# Seconds of one `acmw correct` run of binary $1 writing $2.
time_acmw() {
  local t0 t1
  t0=$(now)
  "$1" correct "$work/trial.csv" -o "$2" --variant drift-centroid --threads 2 --quiet >/dev/null
  t1=$(now)
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.4f\n", b - a }'
}
median() { sort -n | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

: >"$work/ours"
: >"$work/base"
for _ in $(seq "$runs"); do
  time_acmw "$acmw" "$work/acmw_out.csv" >>"$work/ours"
  rm -f "$work"/acmw_out.csv.bak "$work"/acmw_out.csv.acmw.json.bak
  if [ -n "$base" ]; then
    time_acmw "$base" "$work/base_out.csv" >>"$work/base"
    rm -f "$work"/base_out.csv.bak "$work"/base_out.csv.acmw.json.bak
  fi
done
if [ -n "$base" ] && ! cmp -s "$work/acmw_out.csv" "$work/base_out.csv"; then
  echo "the baseline wrote different bytes" >&2
  exit 1
fi
t0=$(now)
python3 "$ref" correct "$work/trial.csv" "$work/ref_out.csv" >/dev/null
t1=$(now)
theirs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.4f\n", b - a }')
ours=$(median <"$work/ours")
printf "acmw correct (drift-centroid, 2 threads), median of %d: %.3f s (runs: %s)\n" \
  "$runs" "$ours" "$(tr '\n' ' ' <"$work/ours")"
if [ -n "$base" ]; then
  based=$(median <"$work/base")
  printf "baseline acmw, median of %d:                         %.3f s (runs: %s)\n" \
    "$runs" "$based" "$(tr '\n' ' ' <"$work/base")"
fi
printf "reference:                                           %.3f s\n" "$theirs"
awk -v o="$ours" -v t="$theirs" 'BEGIN { printf "acmw is %.1fx faster than the reference\n", t / o }'
if [ -n "$base" ]; then
  awk -v b="$based" -v t="$theirs" -v o="$ours" 'BEGIN {
    printf "baseline is %.1fx faster than the reference; acmw takes %.2f of the baseline'"'"'s time\n", t / b, o / b }'
fi
