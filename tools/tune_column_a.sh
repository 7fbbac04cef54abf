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
$pw tune $fs --loop top_composition --method tl "${dt[@]}" --write "$out/tl_top.json"
$pw tune "$out/tl_top.json" --loop bottom_composition --method tl "${dt[@]}" --write "$out/tl.json"
for sc in feed_rate feed_composition; do
  for f in $fs "$out/blt.json" "$out/tl.json"; do
    n=$(basename "$f" .json)
    $pw run "$f" --scenario flowsheets/scenarios/column_a_lv_$sc.json --csv "$out/$n.$sc.csv" --json > "$out/$n.$sc.run.json"
    python3 - "$out/$n.$sc.run.json" "$sc" "$n" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for p in d["paths"]:
    if p["reference"] == "setpoint":
        print(f"{sys.argv[2]:17} {sys.argv[3]:12} {p['path']:20} IAE {p['iae'] / 60:10.4g} min  largest deviation {p['max_deviation']:+.3e}  settled {p['settling_time'] / 60:6.1f} min")
PY
  done
done
