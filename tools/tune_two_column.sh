#!/usr/bin/env bash
# Tuned vs hand-tuned column loops of the two-column plant (issue 16): the temperature/composition loops of
# both columns tuned by BLT from the exact linearization (each column's pair together) and by Tyreus–Luyben
# from relay tests on the nonlinear model (loop by loop), all with a 1-min measurement dead time the model
# leaves out; then two disturbances (+10 kmol/h fresh A; reactor B setpoint +0.035), 10 h each, on each
# file, printing IAE and the largest deviation of the four controlled measurements.
# Usage: tools/tune_two_column.sh [OUTDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/plantwide_tune_two_column}
mkdir -p "$out"
cargo build --release --quiet
pw=target/release/plantwide
fs=flowsheets/two_column_plant.json
dt=(--measurement-dead-time "1 min" --time-unit min)
$pw tune $fs --loops column1_top_T,column1_bottom_T --method blt "${dt[@]}" --write "$out/blt1.json"
$pw tune "$out/blt1.json" --loops column2_top_S,column2_bottom_T --method blt "${dt[@]}" --write "$out/blt.json"
prev=$fs
for loop in column1_top_T column1_bottom_T column2_top_S column2_bottom_T; do
  $pw tune "$prev" --loop $loop --method tl "${dt[@]}" --write "$out/tl_$loop.json"
  prev="$out/tl_$loop.json"
done
cp "$prev" "$out/tl.json"
record='"record": {"interval": "2 min", "time_unit": "h", "paths": ["column1.T[21]", "column1.T[11]", "column2.T[6]", "product.x[S]"]}'
echo "{\"format_version\": 1, \"name\": \"production step\", \"duration\": \"10 h\", \"integrator\": {\"rtol\": 1e-6},
 \"events\": [{\"type\": \"step\", \"at\": \"1 h\", \"path\": \"fresh_A.F\", \"by\": \"10 kmol/h\"}], $record}" > "$out/production.json"
echo "{\"format_version\": 1, \"name\": \"reactor B setpoint step\", \"duration\": \"10 h\", \"integrator\": {\"rtol\": 1e-6},
 \"events\": [{\"type\": \"step\", \"at\": \"1 h\", \"path\": \"reactor_B.sp\", \"by\": 0.035}], $record}" > "$out/composition.json"
for sc in production composition; do
  for f in $fs "$out/blt.json" "$out/tl.json"; do
    n=$(basename "$f" .json)
    $pw run "$f" --scenario "$out/$sc.json" --csv "$out/$n.$sc.csv" --json > "$out/$n.$sc.run.json"
    python3 - "$out/$n.$sc.run.json" "$sc" "$n" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for p in d["paths"]:
    if p["path"] in ("column1.T[21]", "column1.T[11]", "column2.T[6]", "product.x[S]"):
        print(f"{sys.argv[2]:12} {sys.argv[3]:18} {p['path']:15} IAE {p['iae']:11.4g}  largest deviation {p['max_deviation']:+.4g}")
PY
  done
done
