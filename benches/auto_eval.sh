#!/usr/bin/env bash
# `auto` against every single variant and the hindsight-best per-joint
# choice on 24 held-out simulated trials of 120 s (tests/auto_choice.rs:
# seeds 201-224; the weights were tuned on seeds 1-36). Prints, per method,
# the median over trials of the median joint RMS error and the mean worst
# joint, and fails when auto misses its targets (at or below the best single
# variant on both, within 0.3 deg of hindsight on the median).
# Takes minutes: about nine corrections per trial.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --test auto_choice auto_on_24_held_out_trials -- --ignored --nocapture
