#!/usr/bin/env bash
# Times `acmw correct` (reading and writing included) against an independent
# Python implementation of the method on the same 5-minute, 50 Hz, 13-IMU
# trial (drift + centroid), side by side in one run, and prints the ratio.
#
#   benches/cli_vs_reference.sh PATH/TO/acm_ref.py [ACMW_BINARY]
#
# The reference needs python3 with numpy and scipy. ACMW_BINARY defaults to
# the release build under $CARGO_TARGET_DIR (or target/). Nothing in the
# project runs this script; `cargo test` does not need it.
set -euo pipefail
if [ $# -lt 1 ]; then
  echo "usage: $0 PATH/TO/acm_ref.py [ACMW_BINARY]" >&2
  exit 2
fi
ref=$1
acmw=${2:-${CARGO_TARGET_DIR:-$(dirname "$0")/../target}/release/acmw}
[ -f "$ref" ] || { echo "no reference at $ref" >&2; exit 2; }
[ -x "$acmw" ] || { echo "no acmw binary at $acmw (cargo build --release)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$acmw" simulate full-body --duration 300 --seed 5 -o "$work/trial.csv" >/dev/null

now() { date +%s.%N; }
t0=$(now)
"$acmw" correct "$work/trial.csv" -o "$work/acmw_out.csv" --variant drift-centroid --threads 2 --quiet >/dev/null
t1=$(now)
python3 "$ref" correct "$work/trial.csv" "$work/ref_out.csv" >/dev/null
t2=$(now)
awk -v a="$t0" -v b="$t1" -v c="$t2" 'BEGIN {
  ours = b - a; theirs = c - b;
  printf "acmw correct (drift-centroid, 2 threads): %.3f s\n", ours;
  printf "reference:                                %.3f s\n", theirs;
  printf "acmw is %.1fx faster\n", theirs / ours;
}'
