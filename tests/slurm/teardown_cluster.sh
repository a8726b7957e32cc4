#!/usr/bin/env bash
# Stop the private cluster started by tests/slurm/setup_cluster.sh STATE_DIR:
# cancel what is left in its queue, then stop slurmd, slurmctld and munged by
# the PIDs recorded in STATE_DIR/pids (SIGTERM, then SIGKILL after a grace
# period). Only processes this set-up started are signalled: a PID is used
# only while /proc/PID/cmdline still names the expected daemon. Safe to run
# twice, or after a partial start. Also removes the /run/slurm/conf/slurm.conf
# link setup_cluster.sh made (see there).
#
#   tests/slurm/teardown_cluster.sh STATE_DIR
set -uo pipefail

STATE=${1:?usage: teardown_cluster.sh STATE_DIR}
STATE=$(cd "$STATE" 2>/dev/null && pwd) || { echo "[teardown_cluster] no such folder: $1" >&2; exit 0; }
log() { echo "[teardown_cluster] $*" >&2; }

if [ -f "$STATE/slurm.conf" ] && [ -f "$STATE/pids/slurmctld.pid" ]; then
    # Jobs first, so no slurmstepd is left behind once slurmd is gone.
    SLURM_CONF="$STATE/slurm.conf" timeout -k 2 10 scancel --quiet --user="$(id -un)" >/dev/null 2>&1 || true
    for _ in $(seq 1 20); do
        left=$(SLURM_CONF="$STATE/slurm.conf" timeout -k 2 5 squeue -h -t RUNNING,COMPLETING,PENDING 2>/dev/null | wc -l) || break
        [ "$left" = 0 ] && break
        sleep 0.5
    done
fi

# ours PID NAME: the PID still runs the daemon NAME (guards against PID reuse).
ours() { [ -r "/proc/$1/cmdline" ] && tr '\0' ' ' <"/proc/$1/cmdline" | grep -q -- "$2"; }

stop() {
    local name=$1 pidfile="$STATE/pids/$1.pid" pid
    [ -f "$pidfile" ] || return 0
    pid=$(cat "$pidfile")
    if [[ "$pid" =~ ^[0-9]+$ ]] && ours "$pid" "$name"; then
        kill -TERM "$pid" 2>/dev/null || true
        for _ in $(seq 1 30); do
            ours "$pid" "$name" || break
            sleep 0.5
        done
        if ours "$pid" "$name"; then
            log "$name (pid $pid) ignored SIGTERM; sending SIGKILL"
            kill -KILL "$pid" 2>/dev/null || true
        fi
        log "stopped $name (pid $pid)"
    fi
    rm -f "$pidfile"
}

stop slurmd
stop slurmctld
stop munged

# The /run/slurm/conf/slurm.conf link setup_cluster.sh made (only if it still
# points at our slurm.conf), then the folders it created, if empty.
RUNCONF=/run/slurm/conf/slurm.conf
if [ -L "$RUNCONF" ] && [ "$(readlink "$RUNCONF")" = "$STATE/slurm.conf" ]; then
    rm -f "$RUNCONF"
fi
if [ -f "$STATE/created_dirs" ]; then
    tac "$STATE/created_dirs" | while read -r d; do rmdir "$d" 2>/dev/null || true; done
    rm -f "$STATE/created_dirs"
fi
exit 0
