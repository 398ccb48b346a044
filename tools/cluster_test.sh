#!/usr/bin/env bash
# The small study on a real SLURM scheduler: start a single-node SLURM on this machine
# (Debian packages slurmctld/slurmd, installed here when missing), run tests/config/small.yaml
# through `--workflow-profile profiles/slurm`, then check that every output of a local -j2 run
# exists and that the tables and per-object Parquet files are byte-identical to it.
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

snakemake() {  # snakemake on the small config in working directory $1
    local dir=$1; shift
    "$BIN/python" -m snakemake -s "$ROOT/Snakefile" --directory "$dir" \
        --configfile "$SMALL" --replace-workflow-config "$@"
}

# the SLURM run: the workflow's own cluster profile; partition from the environment as a user
# would set it; no accounting daemon here, so no account and squeue for job status
export SBATCH_PARTITION=$PARTITION SBATCH_ACCOUNT=""
snakemake "$WORK/slurm-run" --workflow-profile "$ROOT/profiles/slurm" --jobs 4 \
    --slurm-no-account --slurm-status-command squeue --slurm-init-seconds-before-status-checks 1 \
    figures >"$WORK/slurm-run.log" 2>&1 || { tail -40 "$WORK/slurm-run.log"; fail "the workflow failed under SLURM (log: $WORK/slurm-run.log)"; }
submitted=$(grep -c "Job .* has been submitted with SLURM jobid" "$WORK/slurm-run.log" || true)
[ "$submitted" -gt 0 ] || fail "no job was submitted to SLURM (log: $WORK/slurm-run.log)"
echo "SLURM run done: $submitted jobs through sbatch ($(( $(date +%s) - started )) s)"

snakemake "$WORK/local-run" -j2 figures >"$WORK/local-run.log" 2>&1 \
    || { tail -40 "$WORK/local-run.log"; fail "the local -j2 run failed (log: $WORK/local-run.log)"; }

# every output of the local run exists after the SLURM run, and nothing is left to do
outputs() { (cd "$1/results" && find . -type f ! -path './logs/*' ! -path './benchmarks/*' | sort); }
missing=$(comm -23 <(outputs "$WORK/local-run") <(outputs "$WORK/slurm-run"))
[ -z "$missing" ] || fail "outputs missing after the SLURM run: $missing"
snakemake "$WORK/slurm-run" -n figures 2>&1 | grep -q "Nothing to be done" \
    || fail "after the SLURM run, snakemake -n still finds work to do"
n_outputs=$(outputs "$WORK/local-run" | wc -l)

# the tables and the per-object Parquet files, byte for byte
compared=0
while read -r rel; do
    cmp -s "$WORK/local-run/results/$rel" "$WORK/slurm-run/results/$rel" \
        || fail "results/$rel differs between the SLURM run and the local -j2 run"
    compared=$((compared + 1))
done < <(outputs "$WORK/local-run" | grep -E '^\./(tables/.*\.(csv|md)|objects/.*\.parquet)$')
[ "$compared" -gt 0 ] || fail "no tables were compared"

echo "cluster-test passed: $submitted SLURM jobs, $n_outputs outputs present, $compared tables and" \
     "Parquet files byte-identical to a local -j2 run, $(( $(date +%s) - started )) s in all"
