#!/usr/bin/env bash
# The small study on a real SLURM scheduler: start a single-node SLURM on this machine
# (Debian packages slurmctld/slurmd, installed here when missing), run tests/config/small.yaml
# (`figures`), then 10 of pybullet's random meshes on its grid (`across_objects`), through
# `--workflow-profile profiles/slurm` with its job groups (each object's submitted jobs in one
# group, 20 objects a sbatch job) cut to this node's size; for each, check that every output of a
# local -j2 run exists and that the tables and per-object Parquet and CSV files are
# byte-identical to it, and that the groups sent far fewer jobs through sbatch than the
# submitted jobs they ran, none asking for more than the node has. First, the profile's own
# node size (4 CPUs) on a node with fewer is refused before any job, with one line.
# The daemons started here are stopped by their pid files on exit.
#
#   tools/cluster_test.sh [BIN]      BIN: the venv's bin directory (default .venv/bin)
#
# Needs root (apt-get, /etc/slurm/slurm.conf: srun inside a job reads only the default path).
# Exit status 0 only if the scheduler started, every job ran under it and the outputs match.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
BIN=$(cd "${1:-.venv/bin}" && pwd)
SMALL=$ROOT/tests/config/small.yaml
CONF=/etc/slurm/slurm.conf
PARTITION=main

fail() { echo "cluster-test FAILED: $*" >&2; exit 1; }
started=$(date +%s)

if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v sbatch >/dev/null; then
    [ "$(id -u)" = 0 ] || fail "SLURM is not installed and installing it needs root (apt-get install slurmctld slurmd slurm-client)"
    echo "installing SLURM from Debian's packages"
    { apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q slurmctld slurmd slurm-client; } \
        >/tmp/synergrasp-apt.log 2>&1 || fail "apt-get install slurmctld slurmd slurm-client failed (log: /tmp/synergrasp-apt.log)"
fi
[ "$(id -u)" = 0 ] || fail "the single-node scheduler is started as root (it writes $CONF)"

WORK=$(mktemp -d /tmp/synergrasp-cluster.XXXXXX)
STATE=$WORK/slurm
mkdir -p "$STATE"/{state,spool,log}
BACKUP=""

stop_daemons() {
    for name in slurmd slurmctld; do
        pidfile=$STATE/$name.pid
        if [ -s "$pidfile" ]; then
            pid=$(cat "$pidfile")
            kill "$pid" 2>/dev/null || true
            for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        fi
    done
    if [ -n "$BACKUP" ]; then mv "$BACKUP" "$CONF"; else rm -f "$CONF"; fi
}
finish() {
    status=$?
    stop_daemons
    if [ "$status" = 0 ]; then rm -rf "$WORK"; else echo "kept for inspection: $WORK" >&2; fi
}

if [ -e "$CONF" ]; then
    BACKUP=$WORK/slurm.conf.before
    cp -p "$CONF" "$BACKUP"
fi
trap finish EXIT

HOST=$(hostname -s)
CPUS=$(nproc)
# the node offers all but 1 GB of this machine's memory; every job requests less (README)
MEM_MB=$(( $(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo) - 1024 ))
mkdir -p /etc/slurm
cat >"$CONF" <<EOF
# single-node test cluster written by synergrasp's tools/cluster_test.sh (removed on exit)
ClusterName=local
SlurmctldHost=$HOST(127.0.0.1)
AuthType=auth/none
CredType=cred/none
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
StateSaveLocation=$STATE/state
SlurmdSpoolDir=$STATE/spool
SlurmctldLogFile=$STATE/log/slurmctld.log
SlurmdLogFile=$STATE/log/slurmd.log
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
MinJobAge=3600
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEM_MB State=UNKNOWN
PartitionName=$PARTITION Nodes=ALL Default=YES State=UP MaxTime=INFINITE
EOF

slurmctld -c || fail "the SLURM scheduler could not be started (slurmctld): $(tail -5 "$STATE/log/slurmctld.log" 2>/dev/null)"
slurmd || fail "the SLURM node daemon could not be started (slurmd): $(tail -5 "$STATE/log/slurmd.log" 2>/dev/null)"
for _ in $(seq 60); do
    state=$(sinfo -h -n "$HOST" -o %t 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.5
done
[ "$state" = idle ] || fail "the SLURM scheduler could not be started: node state '${state:-none}' after 30 s
$(tail -5 "$STATE/log/slurmctld.log" 2>/dev/null)
$(tail -5 "$STATE/log/slurmd.log" 2>/dev/null)"
echo "SLURM up: node $HOST, $CPUS CPUs, $MEM_MB MB, partition $PARTITION ($(( $(date +%s) - started )) s)"

# The node's size, which the profile's group jobs are cut to (profiles/slurm: cores, resources mem_mb)
NODE_SIZE=(--cores "$CPUS" --resources "mem_mb=$MEM_MB")  # last: --resources takes every word after it
GROUPED_RULES="mesh_parts|search|simulate|optimise_shard"  # profiles/slurm's groups

snakemake() {  # snakemake in working directory $1 on config file $2
    local dir=$1 config=$2; shift 2
    "$BIN/python" -m snakemake -s "$ROOT/Snakefile" --directory "$dir" \
        --configfile "$config" --replace-workflow-config "$@"
}

slurm_run() {  # the workflow's own cluster profile in directory $1 on config $2, then the arguments
    local dir=$1 config=$2; shift 2
    # partition from the environment as a user would set it; no accounting daemon here, so no
    # account and squeue for job status; a job SLURM holds would hang the run: two hours at most
    # (the ten objects took over 30 min through sbatch on this 2-core machine at a load of 15)
    SBATCH_PARTITION=$PARTITION SBATCH_ACCOUNT="" timeout 7200 "$BIN/python" -m snakemake -s "$ROOT/Snakefile" \
        --directory "$dir" --configfile "$config" --replace-workflow-config \
        --workflow-profile "$ROOT/profiles/slurm" --jobs 4 \
        --slurm-no-account --slurm-status-command squeue --slurm-init-seconds-before-status-checks 1 "$@"
}

# Run TARGET on CONFIG under SLURM (grouped, cut to the node) and locally with -j2; every output
# of the local run must exist after the SLURM run, nothing be left to do, and the tables and
# per-object Parquet files be byte-identical; the group jobs must be fewer than the submitted
# jobs they ran, each within the node. Sets SUBMITTED, UNGROUPED, MAX_CPUS, MAX_MEM_MB,
# MAX_TIME, N_OUTPUTS, COMPARED.
compare_runs() {
    local label=$1 config=$2 target=$3
    local slurm_dir=$WORK/$label-slurm local_dir=$WORK/$label-local
    slurm_run "$slurm_dir" "$config" "$target" "${NODE_SIZE[@]}" >"$slurm_dir.log" 2>&1 \
        || { tail -40 "$slurm_dir.log"; fail "$label: the workflow failed under SLURM (log: $slurm_dir.log)"; }
    SUBMITTED=$(grep -c "Job .* has been submitted with SLURM jobid" "$slurm_dir.log" || true)
    [ "$SUBMITTED" -gt 0 ] || fail "$label: no job was submitted to SLURM (log: $slurm_dir.log)"
    # ungrouped, every job of a submitted rule would be a sbatch job of its own: the run's job stats
    UNGROUPED=$(awk -v rules="^($GROUPED_RULES)\$" '/^Job stats:/ {on = 1; next} on && $1 ~ rules {n += $2} on && $1 == "total" {exit} END {print n + 0}' "$slurm_dir.log")
    [ "$SUBMITTED" -lt "$UNGROUPED" ] || fail "$label: $SUBMITTED sbatch jobs for $UNGROUPED submitted jobs: the profile's groups did not group them"
    # what each sbatch job asked for, as SLURM recorded it (MinJobAge keeps finished jobs an hour)
    MAX_CPUS=0 MAX_MEM_MB=0 MAX_TIME=0
    for id in $(sed -n 's/.*has been submitted with SLURM jobid \([0-9]*\).*/\1/p' "$slurm_dir.log"); do
        read -r cpus mem minutes < <(scontrol show job -o "$id" | awk '{
            for (i = 1; i <= NF; i++) {
                split($i, kv, "=")
                if (kv[1] == "NumCPUs") cpus = kv[2]
                if (kv[1] == "MinMemoryNode") { mem = kv[2]; if (mem ~ /G$/) mem *= 1024; sub(/M$/, "", mem) }
                if (kv[1] == "TimeLimit") { n = split(kv[2], t, ":"); minutes = t[1] * 60 + t[2]; if (n == 2) minutes = t[1] }
            }
            print cpus + 0, mem + 0, minutes + 0 }')
        [ "$cpus" -le "$CPUS" ] && [ "$mem" -le "$MEM_MB" ] \
            || fail "$label: SLURM job $id asked for $cpus CPUs and $mem MB, more than the node's $CPUS CPUs and $MEM_MB MB"
        [ "$cpus" -gt "$MAX_CPUS" ] && MAX_CPUS=$cpus
        [ "$mem" -gt "$MAX_MEM_MB" ] && MAX_MEM_MB=$mem
        [ "$minutes" -gt "$MAX_TIME" ] && MAX_TIME=$minutes
    done
    echo "$label: SLURM run done, $SUBMITTED jobs through sbatch for $UNGROUPED submitted jobs, the largest" \
         "asking $MAX_CPUS CPUs, $MAX_MEM_MB MB, $MAX_TIME min ($(( $(date +%s) - started )) s)"

    snakemake "$local_dir" "$config" -j2 "$target" >"$local_dir.log" 2>&1 \
        || { tail -40 "$local_dir.log"; fail "$label: the local -j2 run failed (log: $local_dir.log)"; }

    outputs() { (cd "$1/results" && find . -type f ! -path './logs/*' ! -path './benchmarks/*' | sort); }
    local missing
    missing=$(comm -23 <(outputs "$local_dir") <(outputs "$slurm_dir"))
    [ -z "$missing" ] || fail "$label: outputs missing after the SLURM run: $missing"
    snakemake "$slurm_dir" "$config" -n "$target" 2>&1 | grep -q "Nothing to be done" \
        || fail "$label: after the SLURM run, snakemake -n still finds work to do"
    N_OUTPUTS=$(outputs "$local_dir" | wc -l)
    COMPARED=0
    while read -r rel; do
        cmp -s "$local_dir/results/$rel" "$slurm_dir/results/$rel" \
            || fail "$label: results/$rel differs between the SLURM run and the local -j2 run"
        COMPARED=$((COMPARED + 1))
    done < <(outputs "$local_dir" | grep -E '^\./(tables/.*\.(csv|md)|objects/.*\.(parquet|csv))$')
    [ "$COMPARED" -gt 0 ] || fail "$label: no tables were compared"
    echo "$label passed: $SUBMITTED SLURM jobs, $N_OUTPUTS outputs present, $COMPARED tables and" \
         "per-object files byte-identical to a local -j2 run, $(( $(date +%s) - started )) s in all"
    # machine-read lines (tools/measurements.py record)
    echo "${label}_sbatch_jobs: $SUBMITTED  (sbatch jobs of the grouped run)"
    echo "${label}_submitted_jobs: $UNGROUPED  (jobs of the submitted rules: the sbatch jobs of an ungrouped run)"
    echo "${label}_largest_request_cpus: $MAX_CPUS  (CPUs of the largest sbatch job, scontrol; the node has $CPUS)"
    echo "${label}_largest_request_mem_mb: $MAX_MEM_MB  (memory of the largest sbatch job, MB, scontrol; the node has $MEM_MB)"
    echo "${label}_largest_request_min: $MAX_TIME  (time limit of the longest sbatch job, min, scontrol)"
    echo "${label}_files_compared: $COMPARED  (tables and per-object files byte-identical to the local run)"
}

# 0. the profile's own node size (4 CPUs, 16000 MB) on a smaller node: refused before any job
if [ "$CPUS" -lt 4 ]; then
    refused=$WORK/refused
    if slurm_run "$refused" "$SMALL" figures >"$refused.log" 2>&1; then
        fail "the profile's 4-CPU groups on this $CPUS-CPU node were not refused (log: $refused.log)"
    fi
    grep -q "more than any node of partition '$PARTITION' has" "$refused.log" \
        || { tail -20 "$refused.log"; fail "the profile's 4-CPU groups on this $CPUS-CPU node failed without the node-size line (log: $refused.log)"; }
    ! grep -q "has been submitted with SLURM jobid" "$refused.log" || fail "a job was submitted before the node-size refusal"
    [ ! -e "$refused/results" ] || [ -z "$(find "$refused/results" -name '*.parquet')" ] || fail "jobs ran before the node-size refusal"
    echo "refused before any job: $(grep -o "a group job may ask for [^;]*" "$refused.log" | head -1)"
fi

# 1. the small study (two boxes)
compare_runs small "$SMALL" figures

# 2. the many-object study spread over the cluster: 10 of pybullet's random meshes
#    (config/examples/random_objects.yaml, n_objects: 10) on the small config's grid and placement
TEN=$WORK/ten_random_objects.yaml
"$BIN/python" - "$SMALL" "$ROOT/config/examples/random_objects.yaml" "$TEN" "$ROOT" <<'PY'
import sys
from pathlib import Path

import yaml

from synergrasp.config import overlay

small, example, out, root = sys.argv[1:]
base = yaml.safe_load(Path(small).read_text())
spec = yaml.safe_load(Path(example).read_text())["random_objects"]
spec = {**spec, "n_objects": 10, "sha256_file": str(Path(root) / spec["sha256_file"])}
config = overlay(base, {"objects": {name: None for name in base["objects"]}, "random_objects": spec})
Path(out).write_text(yaml.safe_dump(config))
PY
compare_runs ten_random_objects "$TEN" across_objects

echo "cluster-test passed: the small study and 10 random objects under SLURM, $(( $(date +%s) - started )) s in all"
