#!/usr/bin/env bash
# Install Kratos MPM 10.4.4 (pinned) into a virtual environment of its own, once: a no-op when
# it imports already. The environment: $IGIMP_KRATOS_VENV, else target/kratos-venv of the
# repository holding this folder. Two studies set up at once (tests run in parallel) take
# turns: the second waits on a lock and then finds Kratos installed.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
venv=${IGIMP_KRATOS_VENV:-$(cd "$here/../../.." && pwd)/target/kratos-venv}
check() {
    "$venv/bin/python" -c "import KratosMultiphysics.MPMApplication, KratosMultiphysics.LinearSolversApplication" > /dev/null 2>&1
}
check && exit 0
mkdir -p "$(dirname "$venv")"
exec 9> "$venv.lock"
command -v flock > /dev/null && flock 9
check && exit 0
echo "installing Kratos MPM 10.4.4 into $venv" >&2
python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --disable-pip-version-check \
    KratosMultiphysics==10.4.4 KratosMPMApplication==10.4.4 KratosLinearSolversApplication==10.4.4
check || { echo "Kratos was installed into $venv but does not import" >&2; exit 1; }
