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
$pw tune $fs --loop reactor_temperature --method tl "${dt[@]}" --write "$out/reactor_T.json"
$pw tune "$out/reactor_T.json" --loop reactor_B --method tl "${dt[@]}" --write "$out/reactor.json"
$pw tune "$out/reactor.json" --loops column1_top_T,column1_bottom_T --method blt "${dt[@]}" --write "$out/blt1.json"
$pw tune "$out/blt1.json" --loops column2_top_S,column2_bottom_T --method blt "${dt[@]}" --write "$out/blt.json"
prev="$out/reactor.json"
for loop in column1_top_T column1_bottom_T column2_top_S column2_bottom_T; do
  $pw tune "$prev" --loop $loop --method tl "${dt[@]}" --write "$out/tl_$loop.json"
  prev="$out/tl_$loop.json"
done
cp "$prev" "$out/tl.json"
for sc in production_step reactor_B_step; do
  for f in $fs "$out/blt.json" "$out/tl.json"; do
    n=$(basename "$f" .json)
    $pw run "$f" --scenario flowsheets/scenarios/two_column_$sc.json --csv "$out/$n.$sc.csv" --json > "$out/$n.$sc.run.json"
    python3 - "$out/$n.$sc.run.json" "$sc" "$n" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for p in d["paths"]:
    if p["reference"] == "setpoint":
        print(f"{sys.argv[2]:12} {sys.argv[3]:18} {p['path']:15} IAE {p['iae']:11.4g}  largest deviation {p['max_deviation']:+.4g}  settled {p['settling_time'] / 3600:5.2f} h  final offset {p['last'] - p['initial'] if p['path'] != 'effluent.x[B]' else float('nan'):+.2e}")
PY
  done
done
