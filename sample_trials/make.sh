#!/usr/bin/env bash
# Regenerates the sample trials from the simulator's presets (deterministic).
# Quaternions are written with 6 decimals (under 1e-4 deg) and only the truth's
# JSON is kept: the workbench simulates the truth again from it when needed.
set -euo pipefail
cd "$(dirname "$0")"
acmw=${ACMW:-../target/release/acmw}
for preset in knee_calf_z15 full_body_clean full_body_drift elbow_20; do
  "$acmw" simulate preset "$preset" --decimals 6 --truth-json-only -o "$preset.csv.gz"
done
# A functional calibration recording (Ricci et al. 2014 protocol), readings to 3 decimals.
"$acmw" simulate calibration --rate 50 --decimals 3 --sloppy TR:30:6 -o child_arms.calib.csv.gz
