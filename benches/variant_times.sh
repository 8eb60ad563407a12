#!/usr/bin/env bash
# Wall and CPU time of `acmw correct` (reading and writing included) per
# variant on one simulated 5-minute, 50 Hz, 13-IMU trial (`acmw simulate
# full-body --duration 300 --seed 5`, as benches/cli_vs_reference.sh), the
# variants interleaved, median of RUNS (default 3) each.
#
#   benches/variant_times.sh [ACMW_BINARY] [VARIANT...]
#
# VARIANTs default to drift-heading-centroid, hinge-heading and auto.
# Nothing in the project runs this script; `cargo test` does not need it.
set -euo pipefail
acmw=${1:-${CARGO_TARGET_DIR:-$(dirname "$0")/../target}/release/acmw}
shift || true
variants=("$@")
[ ${#variants[@]} -gt 0 ] || variants=(drift-heading-centroid hinge-heading auto)
runs=${RUNS:-3}
[ -x "$acmw" ] || { echo "no acmw binary at $acmw (cargo build --release)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$acmw" simulate full-body --duration 300 --seed 5 -o "$work/trial.csv" >/dev/null
median() { sort -n | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
for _ in $(seq "$runs"); do
  for v in "${variants[@]}"; do
    # GNU time's elapsed and user + system seconds.
    /usr/bin/time -f "%e %U %S" -o "$work/t" \
      "$acmw" correct "$work/trial.csv" -o "$work/$v.csv" --variant "$v" --threads 2 --quiet >/dev/null
    read -r wall user sys <"$work/t"
    echo "$wall" >>"$work/$v.wall"
    awk -v u="$user" -v s="$sys" 'BEGIN { print u + s }' >>"$work/$v.cpu"
    rm -f "$work/$v".csv*
  done
done
printf "%-24s %10s %10s   (median of %d, --threads 2)\n" variant "wall s" "cpu s" "$runs"
for v in "${variants[@]}"; do
  printf "%-24s %10.2f %10.2f\n" "$v" "$(median <"$work/$v.wall")" "$(median <"$work/$v.cpu")"
done
