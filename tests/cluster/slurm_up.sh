#!/usr/bin/env bash
# A one-node SLURM cluster on this host, for tests: munged, slurmctld and slurmd
# run as the current user under a temporary folder; stopped again on exit.
#
#   tests/cluster/slurm_up.sh [FOLDER] [-- COMMAND ...]
#
# With a COMMAND, it runs that command with SLURM_CONF set and stops the
# cluster when it ends (exit status of the command). Without one, it prints
# "slurm ready: SLURM_CONF=..." and waits until it is sent SIGTERM or SIGINT.
# FOLDER (default: a new mktemp folder) holds slurm.conf, the munge key and
# socket, the daemons' state, logs and jobcomp.log (one line per finished job).
# One node (this host, 127.0.0.1), one partition "debug", cgroups off
# (proctrack/linuxproc, task/none), no accounting database: job states come
# from squeue and slurmctld; finished jobs are listed in jobcomp.log.
set -euo pipefail

for tool in munged mungekey slurmctld slurmd sinfo; do
    if ! command -v "$tool" >/dev/null 2>&1 && [ ! -x "/usr/sbin/$tool" ]; then
        echo "slurm_up.sh: $tool not found; install it with: apt-get install -y slurm-wlm munge" >&2
        exit 3
    fi
done
export PATH="$PATH:/usr/sbin"

FOLDER="${1:-}"
if [ -z "$FOLDER" ] || [ "$FOLDER" = "--" ]; then FOLDER="$(mktemp -d /tmp/slurm-up.XXXXXX)"; else shift; fi
[ "${1:-}" = "--" ] && shift
mkdir -p "$FOLDER"/{state,spool,log,munge}
FOLDER="$(cd "$FOLDER" && pwd)"
chmod 700 "$FOLDER/munge"

free_port() {
    python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}
NODE="$(hostname -s)"
USER_NAME="$(id -un)"
read -r CPUS MEMORY < <(slurmd -C | awk '/^NodeName/ {for (i = 1; i <= NF; i++) {split($i, kv, "="); v[kv[1]] = kv[2]} print v["CPUs"], v["RealMemory"]}')
CTLD_PORT="$(free_port)"
SLURMD_PORT="$(free_port)"

cat > "$FOLDER/slurm.conf" <<CONF
ClusterName=pinfeedtest
SlurmctldHost=$NODE(127.0.0.1)
SlurmUser=$USER_NAME
SlurmdUser=$USER_NAME
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$FOLDER/munge/munge.sock
StateSaveLocation=$FOLDER/state
SlurmdSpoolDir=$FOLDER/spool
SlurmctldPidFile=$FOLDER/slurmctld.pid
SlurmdPidFile=$FOLDER/slurmd.pid
SlurmctldLogFile=$FOLDER/log/slurmctld.log
SlurmdLogFile=$FOLDER/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$FOLDER/jobcomp.log
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
MpiDefault=none
ReturnToService=2
MinJobAge=600
SlurmdTimeout=60
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEMORY State=UNKNOWN
PartitionName=debug Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$FOLDER/slurm.conf"
# The Snakemake SLURM job step drops SLURM_* variables (SLURM_CONF too) before
# its inner srun, which then looks at the compiled-in /etc/slurm/slurm.conf:
# with SLURM_UP_SYSTEM_CONF=1 (and no such file yet) link it there while up.
SYSTEM_CONF=/etc/slurm/slurm.conf
LINKED_SYSTEM_CONF=""
if [ "${SLURM_UP_SYSTEM_CONF:-0}" = "1" ] && [ ! -e "$SYSTEM_CONF" ] && mkdir -p /etc/slurm 2>/dev/null \
        && ln -s "$SLURM_CONF" "$SYSTEM_CONF" 2>/dev/null; then
    LINKED_SYSTEM_CONF="$SYSTEM_CONF"
fi

stop_cluster() {
    if [ -n "$LINKED_SYSTEM_CONF" ]; then rm -f "$LINKED_SYSTEM_CONF"; fi
    for pidfile in "$FOLDER/slurmd.pid" "$FOLDER/slurmctld.pid" "$FOLDER/munge/munged.pid"; do
        if [ -s "$pidfile" ]; then kill "$(cat "$pidfile")" 2>/dev/null || true; fi
    done
}
trap stop_cluster EXIT
trap 'exit 143' TERM INT

mungekey --create --keyfile="$FOLDER/munge/munge.key" --force 2>/dev/null \
    || dd if=/dev/urandom of="$FOLDER/munge/munge.key" bs=1024 count=1 status=none
chmod 600 "$FOLDER/munge/munge.key"
munged --force --key-file="$FOLDER/munge/munge.key" --socket="$FOLDER/munge/munge.sock" \
    --pid-file="$FOLDER/munge/munged.pid" --log-file="$FOLDER/log/munged.log" \
    --seed-file="$FOLDER/munge/munged.seed"
slurmctld -i
slurmd -N "$NODE"

for _ in $(seq 60); do
    if [ "$(sinfo -h -n "$NODE" -o %t 2>/dev/null)" = "idle" ]; then break; fi
    sleep 1
done
if [ "$(sinfo -h -n "$NODE" -o %t 2>/dev/null)" != "idle" ]; then
    echo "slurm_up.sh: node $NODE did not become idle within 60 s; logs in $FOLDER/log" >&2
    exit 4
fi

if [ $# -gt 0 ]; then
    "$@"
    exit $?
fi
echo "slurm ready: SLURM_CONF=$SLURM_CONF"
while true; do sleep 3600 & wait $!; done
