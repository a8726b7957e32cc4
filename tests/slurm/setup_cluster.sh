#!/usr/bin/env bash
# Start a private single-node SLURM cluster on localhost for tests/test_slurm.py.
#
#   tests/slurm/setup_cluster.sh STATE_DIR
#
# Everything (munge key and socket, slurm.conf, spool/state folders, logs, PID
# files) lives in STATE_DIR; nothing under /etc is changed and no system
# service is touched (we use our own munge socket and our own ports). The one
# thing outside STATE_DIR is a link /run/slurm/conf/slurm.conf -> our
# slurm.conf while the cluster is up (see "host check"); exit code 3 means the
# host already has a SLURM configuration and nothing was started. Needs root. Installs
# Debian's slurm-wlm + munge first when missing (apt-get update once, then
# apt-get install -y slurm-wlm munge).
#
# On success the last line on stdout is `SLURM_CONF=STATE_DIR/slurm.conf`;
# clients (sbatch, squeue, sinfo, scontrol) must run with that variable set.
# The daemons run in the background; their PIDs are in STATE_DIR/pids/*.pid.
# Stop them with tests/slurm/teardown_cluster.sh STATE_DIR (also after a
# failed start: it stops whatever was started).
#
# Optional environment: SLURMCTLD_PORT / SLURMD_PORT (defaults 16817/16818),
# SLURM_SETUP_TIMEOUT (seconds to wait for each daemon, default 60).
# Design notes (no cgroups, no systemd, no slurmdbd):
#   ProctrackType=proctrack/linuxproc, TaskPlugin=task/none,
#   JobAcctGatherType=jobacct_gather/none, AccountingStorageType=accounting_storage/none;
#   RealMemory from `slurmd -C` (more than that and the node drains);
#   MinJobAge=14400 so finished jobs stay visible to `squeue` (no sacct here) for
#   the whole tiny workflow run (the test lists every job it submitted).
set -euo pipefail

STATE=${1:?usage: setup_cluster.sh STATE_DIR}
CTLD_PORT=${SLURMCTLD_PORT:-16817}
SLURMD_PORT=${SLURMD_PORT:-16818}
WAIT=${SLURM_SETUP_TIMEOUT:-60}
NODE=animsynth-node

log() { echo "[setup_cluster] $*" >&2; }
die() { log "ERROR: $*"; exit 1; }

[ "$(id -u)" = 0 ] || die "must run as root (it installs packages and runs the SLURM daemons)"

# ---------------------------------------------------------------- install
need_install=0
for exe in munged munge unmunge mungekey slurmctld slurmd sbatch squeue sinfo scontrol srun; do
    command -v "$exe" >/dev/null 2>&1 || need_install=1
done
if [ "$need_install" = 1 ]; then
    command -v apt-get >/dev/null 2>&1 || die "slurm-wlm/munge missing and apt-get unavailable"
    log "installing slurm-wlm and munge (apt-get update; apt-get install -y slurm-wlm munge)"
    export DEBIAN_FRONTEND=noninteractive
    timeout -k 10 600 apt-get update -q >&2 || die "apt-get update failed"
    timeout -k 10 900 apt-get install -y -q --no-install-recommends slurm-wlm munge >&2 \
        || die "apt-get install slurm-wlm munge failed"
fi
for exe in munged munge unmunge mungekey slurmctld slurmd sbatch squeue sinfo scontrol srun; do
    command -v "$exe" >/dev/null 2>&1 || die "$exe still missing after installation"
done

# ---------------------------------------------------------------- host check
# The plugin's job step (snakemake-executor-plugin-slurm-jobstep) removes all
# SLURM_* variables, SLURM_CONF included, before its nested `srun`; that srun
# then finds its configuration the way clients on a configless cluster do:
# /etc/slurm/slurm.conf, else /run/slurm/conf/slurm.conf. So we link
# /run/slurm/conf/slurm.conf to our slurm.conf (teardown removes the link),
# and refuse (exit 3) on a host that already has a SLURM configuration there.
RUNCONF=/run/slurm/conf/slurm.conf
if [ -e /etc/slurm/slurm.conf ]; then
    log "this host already has /etc/slurm/slurm.conf (a real SLURM set-up); not starting a private test cluster beside it"
    exit 3
fi
# A link left by an earlier test cluster that was killed before its teardown
# (its folder gone, or none of its daemons alive any more) is stale: remove it.
if [ -L "$RUNCONF" ]; then
    old_state=$(dirname "$(readlink "$RUNCONF")")
    alive=0
    for f in "$old_state"/pids/*.pid; do
        [ -f "$f" ] || continue
        pid=$(cat "$f")
        name=$(basename "$f" .pid)
        [[ "$pid" =~ ^[0-9]+$ ]] && [ -r "/proc/$pid/cmdline" ] \
            && tr '\0' ' ' <"/proc/$pid/cmdline" | grep -q -- "$name" && alive=1
    done
    if [ ! -e "$RUNCONF" ] || { [ -d "$old_state/pids" ] && [ "$alive" = 0 ]; }; then
        log "removing stale $RUNCONF -> $(readlink "$RUNCONF") (its test cluster is gone)"
        rm -f "$RUNCONF"
    fi
fi
if [ -e "$RUNCONF" ] || [ -L "$RUNCONF" ]; then
    log "$RUNCONF already exists (a configless SLURM node or another test cluster); not starting a private test cluster"
    exit 3
fi

# ---------------------------------------------------------------- layout
mkdir -p "$STATE"
STATE=$(cd "$STATE" && pwd)
mkdir -p "$STATE/pids" "$STATE/munge" "$STATE/ctld" "$STATE/spool" "$STATE/log"
chmod 0755 "$STATE/munge"
SOCK="$STATE/munge/munge.socket.2"
[ "${#SOCK}" -lt 100 ] || die "munge socket path too long for a UNIX socket: $SOCK"

# start_daemon NAME CMD...: run CMD in the foreground mode of the daemon, in
# its own session, detached from our stdio (so callers waiting on our stdout
# do not hang), and record its PID.
start_daemon() {
    local name=$1
    shift
    setsid "$@" </dev/null >"$STATE/log/$name.out" 2>&1 &
    echo $! >"$STATE/pids/$name.pid"
    log "started $name (pid $!)"
}

# wait_for WHAT CMD...: poll CMD until it succeeds, at most $WAIT seconds.
wait_for() {
    local what=$1
    shift
    local t=0
    until "$@" >/dev/null 2>&1; do
        t=$((t + 1))
        if [ "$t" -ge "$((WAIT * 2))" ]; then
            log "timed out after ${WAIT}s waiting for $what; last lines of the logs:"
            tail -n 20 "$STATE"/log/* >&2 || true
            exit 1
        fi
        sleep 0.5
    done
}

# ---------------------------------------------------------------- munge
# Own key, socket, pid, log and seed file; munged runs as root (the key must
# belong to the user munged runs as), so /etc/munge and /run/munge are untouched.
KEY="$STATE/munge/munge.key"
[ -f "$KEY" ] || mungekey --create --keyfile="$KEY" >&2
chmod 0600 "$KEY"
start_daemon munged munged --foreground --force --socket="$SOCK" --key-file="$KEY" \
    --pid-file="$STATE/munge/munged.pid" --log-file="$STATE/log/munged.log" \
    --seed-file="$STATE/munge/munged.seed"
munge_ok() { munge --socket="$SOCK" -n | unmunge --socket="$SOCK"; }
wait_for munged munge_ok

# ---------------------------------------------------------------- slurm.conf
HOST=$(hostname -s)
# `slurmd -C` prints the node's real layout, e.g.
# NodeName=vm CPUs=2 Boards=1 SocketsPerBoard=1 CoresPerSocket=2 ThreadsPerCore=1 RealMemory=24105
HW=$(timeout -k 5 30 slurmd -C | head -n 1)
CPUS=$(sed -n 's/.*CPUs=\([0-9]*\).*/\1/p' <<<"$HW")
MEM=$(sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' <<<"$HW")
[ -n "$CPUS" ] && [ -n "$MEM" ] || die "cannot parse 'slurmd -C' output: $HW"
LAYOUT=$(grep -o 'CPUs=.*' <<<"$HW" | sed 's/ *RealMemory=[0-9]*//')

cat >"$STATE/slurm.conf" <<EOF
# Written by tests/slurm/setup_cluster.sh: one node on localhost, no cgroups,
# no accounting database (sacct does not work; query with squeue).
ClusterName=animsynth
SlurmctldHost=${HOST}(127.0.0.1)
SlurmctldPort=${CTLD_PORT}
SlurmdPort=${SLURMD_PORT}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=${SOCK}
CredType=cred/munge
StateSaveLocation=${STATE}/ctld
SlurmdSpoolDir=${STATE}/spool
SlurmctldPidFile=${STATE}/pids/slurmctld.daemon.pid
SlurmdPidFile=${STATE}/pids/slurmd.daemon.pid
SlurmctldLogFile=${STATE}/log/slurmctld.log
SlurmdLogFile=${STATE}/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MailProg=/bin/true
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
DefMemPerCPU=512
MinJobAge=14400
ReturnToService=2
SlurmdTimeout=300
InactiveLimit=0
KillWait=5
NodeName=${NODE} NodeHostname=${HOST} NodeAddr=127.0.0.1 ${LAYOUT} RealMemory=${MEM} State=UNKNOWN
PartitionName=debug Nodes=${NODE} Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$STATE/slurm.conf"
# Record what we create under /run so teardown removes exactly that.
[ -d /run/slurm ] || echo /run/slurm >>"$STATE/created_dirs"
[ -d /run/slurm/conf ] || echo /run/slurm/conf >>"$STATE/created_dirs"
mkdir -p /run/slurm/conf
ln -s "$SLURM_CONF" "$RUNCONF"

# ---------------------------------------------------------------- daemons
start_daemon slurmctld slurmctld -D -i -f "$SLURM_CONF"
wait_for slurmctld timeout -k 2 5 scontrol ping
start_daemon slurmd slurmd -D -N "$NODE" -f "$SLURM_CONF"
node_idle() { [ "$(timeout -k 2 5 sinfo -h -n "$NODE" -o %t)" = idle ]; }
wait_for "node $NODE to become idle" node_idle
log "cluster up: $(timeout -k 2 5 sinfo -h -o '%P %D %t %c CPUs %m MB')"
echo "SLURM_CONF=$SLURM_CONF"
