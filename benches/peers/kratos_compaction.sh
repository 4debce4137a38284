#!/usr/bin/env bash
# The peer bench of issue 47: time per Newton iteration of the plane-strain compaction
# (§5.2, 40 load steps, gravity ramped to W = 4e5) with Kratos MPM 10.4.4 (standard MPM,
# Hencky elasticity through its Hencky–Mohr–Coulomb law with a cohesion never reached,
# sparse LU) beside igimp's `mpm` and iGIMP, one thread each, interleaved, at h = 1/4 and
# 1/8. Installs Kratos into a virtual environment of its own on first use (pip; the
# packages are listed below).
#
#   bash benches/peers/kratos_compaction.sh [repeats] [cells per unit length ...]
#
# Prints one CSV row per run and writes them to target/peers/kratos_compaction.csv; a
# failing run is a row with its reason, never the end of the bench.
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
repeats=${1:-3}
shift || true
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(4 8)
venv=${KRATOS_VENV:-$root/target/kratos-venv}
out=$root/target/peers
mkdir -p "$out"
if ! "$venv/bin/python" -c "import KratosMultiphysics.MPMApplication" > /dev/null 2>&1; then
    echo "installing Kratos 10.4.4 into $venv" >&2
    python3 -m venv "$venv" && "$venv/bin/pip" install -q KratosMultiphysics==10.4.4 \
        KratosMPMApplication==10.4.4 KratosLinearSolversApplication==10.4.4 \
        KratosConstitutiveLawsApplication==10.4.4 KratosStructuralMechanicsApplication==10.4.4 \
        || { echo "Kratos could not be installed: the igimp rows only" >&2; }
fi
bench=$(cd "$root" && cargo bench --bench small_cases --no-run 2>&1 \
    | sed -n 's/.*Executable .*(\(.*small_cases-[0-9a-f]*\)).*/\1/p' | tail -1)
[ -x "$root/$bench" ] && bench=$root/$bench
[ -x "$bench" ] || { echo "could not build benches/small_cases.rs" >&2; exit 1; }
csv=$out/kratos_compaction.csv
echo "code,method,h,newton_iterations,seconds,ms_per_iteration,steps_done,failure" | tee "$csv"
for n in "${sizes[@]}"; do
    for r in $(seq "$repeats"); do
        # Kratos
        case_dir=$out/kratos-h$n
        if "$venv/bin/python" "$root/benches/peers/kratos/make_case.py" "$case_dir" --h "$(python3 -c "print(1/$n)")" \
            --law hencky --linsolver sparse_lu --steps 40 --echo 0 > /dev/null 2>&1 \
            && OMP_NUM_THREADS=1 "$venv/bin/python" "$root/benches/peers/kratos/run_kratos.py" "$case_dir" \
                > "$case_dir/run.log" 2>&1; then
            python3 - "$case_dir/result.json" "$n" <<'PY' | tee -a "$csv"
import json, sys
r = json.load(open(sys.argv[1]))
its = r["newton_iterations"]
fail = (r["failure"] or {}).get("error", "") if r["failure"] else ""
print(f"kratos,mpm,1/{sys.argv[2]},{its},{r['loop_seconds']:.3f},{1e3 * r['loop_seconds'] / max(its, 1):.2f},{r['steps_done']},\"{fail.replace(chr(34), chr(39))}\"")
PY
        else
            echo "kratos,mpm,1/$n,,,,,\"$(tail -1 "$case_dir/run.log" 2>/dev/null | tr -d '"')\"" | tee -a "$csv"
        fi
        # igimp, both methods (the bench's own rows: phases by name)
        for basis in mpm igimp; do
            BASIS=$basis REPEATS=1 RAYON_NUM_THREADS=1 "$bench" "$n" | grep "^compaction," | tail -1 | python3 -c "
import sys
f = sys.stdin.read().strip().split(',', 13)
print(f'igimp,{f[1]},1/$n,{f[4]},{f[5]},{f[6]},,\"{f[13] if len(f) > 13 else \"\"}\"')" | tee -a "$csv"
        done
    done
done
