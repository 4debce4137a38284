#!/usr/bin/env bash
# Run a study on a Slurm cluster: N array tasks (one shard each), then a merge job that
# depends on all of them.
#
#   bash examples/slurm/submit.sh compaction 8           # full tier, 8 shards
#   TIER=quick bash examples/slurm/submit.sh column 4    # quick tier
#   WAIT=1 ...                                           # block until the merge is done
#
# Run from the repository root; the release binary is built first (once, on the login node).
set -euo pipefail
STUDY="${1:?usage: submit.sh <study> <shards>}"
N="${2:?usage: submit.sh <study> <shards>}"
here="$(cd "$(dirname "$0")" && pwd)"
# SKIP_BUILD=1 uses an existing target/release/study (CI: the one `cargo test --release` built).
[ -n "${SKIP_BUILD:-}" ] || cargo build --release --locked --bin study
export STUDY TIER="${TIER:-}" OUT="${OUT:-reports}" STUDY_BIN="${STUDY_BIN:-$PWD/target/release/study}"
# The jobs' logs go under the output folder, beside (not inside) the study's folder, which
# the merge replaces as a whole; Slurm does not create the folder itself.
logs="$OUT/slurm-logs"
mkdir -p "$logs"
array=$(sbatch --parsable --export=ALL --array="0-$((N - 1))" \
    --output="$logs/%x-%A_%a.out" "$here/shard.sbatch")
merge=$(sbatch --parsable --export=ALL --dependency="afterok:${array%%;*}" \
    --output="$logs/%x-%j.out" ${WAIT:+--wait} "$here/merge.sbatch")
echo "submitted shards $array (array of $N) and merge $merge; results in $OUT/$STUDY/, logs in $logs/"
