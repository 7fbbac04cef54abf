#!/usr/bin/env bash
# Tuned vs hand-tuned quality loops of the two-column plant (issue 16): the reactor's temperature and
# B-composition loops tuned by Tyreus–Luyben from relay tests (both files), the temperature/composition loops of
# both columns by BLT from the exact linearization (each column's pair together) or by Tyreus–Luyben loop by
# loop, all with a 1-min measurement dead time the model leaves out; then the shipped disturbances
# (flowsheets/scenarios/two_column_production_step.json, two_column_reactor_B_step.json) on each file, printing
# IAE and the largest deviation of the six controlled measurements.
# Usage: tools/tune_two_column.sh [OUTDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/plantwide_tune_two_column}
mkdir -p "$out"
cargo build --release --quiet
pw=target/release/plantwide
fs=flowsheets/two_column_plant.json
dt=(--measurement-dead-time "1 min" --time-unit min)
$pw tune $fs --loops reactor_temperature,reactor_B --method tl "${dt[@]}" --write "$out/reactor.json"
$pw tune "$out/reactor.json" --loops column1_top_T,column1_bottom_T --method blt "${dt[@]}" --write "$out/blt1.json"
$pw tune "$out/blt1.json" --loops column2_top_S,column2_bottom_T --method blt "${dt[@]}" --write "$out/blt.json"
$pw tune "$out/reactor.json" --loops column1_top_T,column1_bottom_T,column2_top_S,column2_bottom_T --method tl "${dt[@]}" \
  --write "$out/tl.json"
tools/compare_runs.sh "$out" h "flowsheets/scenarios/two_column_production_step.json flowsheets/scenarios/two_column_reactor_B_step.json" $fs "$out/blt.json" "$out/tl.json"
