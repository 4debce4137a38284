#!/usr/bin/env bash
# One case: adapter.py under the environment setup.sh made, one thread (OpenMP).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
venv=${IGIMP_KRATOS_VENV:-$(cd "$here/../../.." && pwd)/target/kratos-venv}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
exec "$venv/bin/python" "$here/adapter.py" "$@"
