#!/usr/bin/env bash
# Latency of `acmw follow` (row written -> corrected row read from its output,
# real time at 50 Hz) and the RMS difference between live (extrapolated) and
# final joint angles per joint and variant, on sample_trials/full_body_drift.
# FOLLOW_LATENCY_S (default 60) seconds of real time; FOLLOW_VARIANT.
set -euo pipefail
cd "$(dirname "$0")/.."
exec cargo bench --bench follow_latency "$@"
