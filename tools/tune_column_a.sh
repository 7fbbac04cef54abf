#!/usr/bin/env bash
# Tuned vs first-guess composition loops of column A (issue 16): flowsheets/column_a_lv.json tuned by BLT from
# the exact linearization and by Tyreus–Luyben from relay tests on the nonlinear model (top loop first, then the
# bottom loop with the top one in auto), both told of the analyzers' 1.5 min of effective delay; then the shipped
# feed-rate and feed-composition steps on each file, printing IAE, largest deviation and settling time.
# Usage: tools/tune_column_a.sh [OUTDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/plantwide_tune_column_a}
mkdir -p "$out"
cargo build --release --quiet
pw=target/release/plantwide
fs=flowsheets/column_a_lv.json
dt=(--measurement-dead-time "1.5 min" --time-unit min)
$pw tune $fs --loops top_composition,bottom_composition --method blt "${dt[@]}" --write "$out/blt.json"
$pw tune $fs --loops top_composition,bottom_composition --method tl "${dt[@]}" --write "$out/tl.json"
tools/compare_runs.sh "$out" min "flowsheets/scenarios/column_a_lv_feed_rate.json flowsheets/scenarios/column_a_lv_feed_composition.json" $fs "$out/blt.json" "$out/tl.json"
