#!/usr/bin/env bash
# Install and start a single-node Slurm (Debian's slurm-wlm and munge) for CI, then run the
# example job array of examples/slurm/ on the quick tier of the column study and check that
# the merged results.json equals an unsharded run's (timing aside). Needs root.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v slurmctld >/dev/null; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -q >/dev/null
    # Without the recommended packages: 61 packages to resolve instead of 211 (apt-cache
    # depends --recurse, 2026-12-03); slurmd/slurmctld need none of them here.
    apt-get install -y -q --no-install-recommends slurm-wlm munge >/dev/null
fi
host="$(hostname -s)"
cpus="$(nproc)"
mem="$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 512 ))"
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm /run/munge
cat > /etc/slurm/slurm.conf <<CONF
ClusterName=ci
SlurmctldHost=${host}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
NodeName=${host} CPUs=${cpus} RealMemory=${mem} State=UNKNOWN
PartitionName=ci Nodes=${host} Default=YES MaxTime=INFINITE State=UP
CONF
[ -f /etc/munge/munge.key ] || (dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key 2>/dev/null)
chown -R munge:munge /etc/munge /run/munge /var/lib/munge /var/log/munge 2>/dev/null || true
chmod 400 /etc/munge/munge.key
pgrep -x munged >/dev/null || su -s /bin/sh munge -c "munged" || munged --force
pgrep -x slurmctld >/dev/null || slurmctld
pgrep -x slurmd >/dev/null || slurmd
for _ in $(seq 60); do
    sinfo -h -o %t 2>/dev/null | grep -qE '^idle' && break
    sleep 1
done
sinfo
out="$(mktemp -d)"
[ -x target/release/study ] || cargo build --release --locked --bin study
OUT="$out/sharded" TIER=quick WAIT=1 SKIP_BUILD=1 bash examples/slurm/submit.sh column 3
target/release/study column --quick --out "$out/whole" >/dev/null 2>&1
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
a = json.load(open(f"{out}/sharded/column/results.json"))
b = json.load(open(f"{out}/whole/column/results.json"))
for r in (a, b):
    r.pop("timing")
    for c in r["cases"]:
        c["wall_seconds"] = 0
assert a == b, "merged Slurm run differs from the unsharded run"
import glob, os
logs = sorted(os.path.basename(p) for p in glob.glob(f"{out}/sharded/slurm-logs/*.out"))
assert len(logs) == 4, f"expected 3 shard logs and a merge log under the output folder: {logs}"
assert not glob.glob("igimp-*.out"), "a Slurm log was written to the repository root"
print(f"slurm: {len(a['cases'])} cases in 3 array tasks, merged results equal the unsharded run; logs {logs}")
PY
