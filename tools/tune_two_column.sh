#!/usr/bin/env bash
# Tuned vs hand-tuned temperature loops of column 1 of the two-column plant (issue 16): BLT from the
# exact linearization and Tyreus–Luyben from relay tests on the nonlinear model (loop by loop, the
# top loop first), both with a 1-min measurement dead time that the model leaves out; then the
# production step (+10 kmol/h of fresh A at 1 h, 10 h) on each file, printing IAE and the largest
# deviation of the controlled temperatures. Usage: tools/tune_two_column.sh [OUTDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/plantwide_tune_two_column}
mkdir -p "$out"
cargo build --release --quiet
pw=target/release/plantwide
fs=flowsheets/two_column_plant.json
dt=(--measurement-dead-time "1 min" --time-unit min)
$pw tune $fs --loops column1_top_T,column1_bottom_T --method blt "${dt[@]}" --write "$out/blt.json"
$pw tune $fs --loop column1_top_T --method tl "${dt[@]}" --write "$out/tl_top.json"
$pw tune "$out/tl_top.json" --loop column1_bottom_T --method tl "${dt[@]}" --write "$out/tl.json"
cat > "$out/production_step.json" <<'SC'
{"format_version": 1, "name": "production step", "duration": "10 h", "integrator": {"rtol": 1e-6},
 "events": [{"type": "step", "at": "1 h", "path": "fresh_A.F", "by": "10 kmol/h"}],
 "record": {"interval": "2 min", "time_unit": "h", "paths": ["column1.T[21]", "column1.T[11]", "column2.T[6]", "product.x[S]"]}}
SC
for f in $fs "$out/blt.json" "$out/tl.json"; do
  n=$(basename "$f" .json)
  $pw run "$f" --scenario "$out/production_step.json" --csv "$out/$n.csv" --json > "$out/$n.run.json"
  python3 - "$out/$n.run.json" "$n" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for p in d["paths"]:
    if p["path"] in ("column1.T[21]", "column1.T[11]"):
        print(f"{sys.argv[2]:18} {p['path']:15} IAE {p['iae']:9.1f} K·s  largest deviation {p['max_deviation']:+.4f} K")
PY
done
