#!/usr/bin/env bash
# Install Kratos MPM 10.4.4 (pinned) into a virtual environment of its own, once: a no-op when
# it imports already. The environment: $IGIMP_KRATOS_VENV, else target/kratos-venv of the
# repository holding this folder.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
venv=${IGIMP_KRATOS_VENV:-$(cd "$here/../../.." && pwd)/target/kratos-venv}
if "$venv/bin/python" -c "import KratosMultiphysics.MPMApplication, KratosMultiphysics.LinearSolversApplication" > /dev/null 2>&1; then
    exit 0
fi
echo "installing Kratos MPM 10.4.4 into $venv" >&2
python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --disable-pip-version-check \
    KratosMultiphysics==10.4.4 KratosMPMApplication==10.4.4 KratosLinearSolversApplication==10.4.4
"$venv/bin/python" -c "import KratosMultiphysics.MPMApplication, KratosMultiphysics.LinearSolversApplication" > /dev/null
