#!/usr/bin/env bash
# Checks sharding the way a cluster runs it: N simulated trials corrected by
# 4 shards started at once by GNU parallel (installed from the distribution's
# packages when missing), merged, against one unsharded run: outputs byte for
# byte, manifest rows but for wall times. Exits non-zero on any difference.
#
#   scripts/shards_with_parallel.sh [N=12] [ACMW_BINARY]
#
# tests/batch.rs checks the same without GNU parallel (it starts the shards
# itself); this script is the README's command line run for real.
set -euo pipefail
n=${1:-12}
acmw=$(realpath "${2:-${CARGO_TARGET_DIR:-$(dirname "$0")/../target}/release/acmw}")
[ -x "$acmw" ] || { echo "no acmw binary at $acmw (cargo build --release)" >&2; exit 2; }
if ! command -v parallel >/dev/null; then
  if command -v apt-get >/dev/null; then
    apt-get install -y parallel >/dev/null || { apt-get update >/dev/null && apt-get install -y parallel >/dev/null; }
  else
    echo "GNU parallel is missing and cannot be installed here" >&2; exit 2
  fi
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/a/trials" "$work/b"
for ((k = 0; k < n; k++)); do
  extra=()
  ((k % 3 == 0)) && extra+=(--drift l_calf:30:0.05)
  "$acmw" simulate full-body --duration 120 --seed $((2000 + k)) --truth-json-only \
    "${extra[@]}" -o "$work/a/trials/t$(printf %03d "$k").csv.gz" >/dev/null
done
cp -r "$work/a/trials" "$work/b/trials"
# The README's line, on this machine.
(cd "$work/a" && parallel --will-cite "$acmw" batch trials --out out --shard {}/4 --jobs 1 --quiet ::: 1 2 3 4 \
  && "$acmw" batch --merge --out out)
(cd "$work/b" && "$acmw" batch trials --out out --jobs 2 --quiet)
# The CSV manifests without their last column (wall_s).
strip() { sed 's/,[^,]*$//' "$1"; }
status=0
diff <(strip "$work/a/out/manifest.csv") <(strip "$work/b/out/manifest.csv") || status=1
for f in "$work/b/out"/t*; do
  cmp "$f" "$work/a/out/$(basename "$f")" || status=1
done
[ "$(ls "$work/a/out"/t* | wc -l)" = "$(ls "$work/b/out"/t* | wc -l)" ] || status=1
for k in 1 2 3 4; do
  printf 'shard %d/4: %s trials\n' "$k" "$(tail -n +2 "$work/a/out/manifest.shard-$k-of-4.csv" | wc -l)"
done
if [ $status = 0 ]; then
  echo "4 shards under GNU parallel, merged = one unsharded run ($n trials): outputs byte for byte, manifest rows but for wall times"
else
  echo "sharded and unsharded runs differ" >&2
fi
exit $status
