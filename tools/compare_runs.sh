#!/usr/bin/env bash
# Run each flowsheet through each scenario and print, for every recorded path on a setpoint, its IAE,
# largest deviation and settling time (IAE and times in TIME_UNIT: s, min or h) — the comparison table of
# tools/tune_column_a.sh and tools/tune_two_column.sh.
# Usage: tools/compare_runs.sh OUTDIR TIME_UNIT "SCENARIO..." FLOWSHEET...
set -euo pipefail
out=$1 unit=$2 scenarios=$3
shift 3
pw=target/release/plantwide
for sc in $scenarios; do
  for f in "$@"; do
    n=$(basename "$f" .json)
    s=$(basename "$sc" .json)
    $pw run "$f" --scenario "$sc" --csv "$out/$n.$s.csv" --json > "$out/$n.$s.run.json"
    python3 - "$out/$n.$s.run.json" "$s" "$n" "$unit" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
unit = sys.argv[4]
per = {"s": 1.0, "min": 60.0, "h": 3600.0}[unit]
for p in d["paths"]:
    if p["reference"] == "setpoint":
        print(f"{sys.argv[2]:30} {sys.argv[3]:18} {p['path']:20} IAE {p['iae'] / per:11.4g} {unit}  "
              f"largest deviation {p['max_deviation']:+.4g}  settled {(p['settling_time'] or 0) / per:7.2f} {unit}  "
              f"end offset {p['last'] - p['initial']:+.2e}")
PY
  done
done
