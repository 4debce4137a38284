#!/usr/bin/env bash
# igimp solves the case; then the first point's sigma_xx becomes NaN, as Python's json writes it.
set -euo pipefail
"$1" --solve-case "$2" "$3"
python3 - "$3" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
r["fields"]["cauchy"][0][0] = float("nan")
json.dump(r, open(sys.argv[1], "w"))
PY
