#!/usr/bin/env bash
# Stops the local single-node Slurm cluster started by start-local-cluster.sh (slurmd, slurmctld, munged); run as root.
set -euo pipefail

log() { echo "[stop-local-cluster] $*" >&2; }

stop_pidfile() {  # $1 = pidfile, $2 = process name (used only if the pidfile is missing/stale)
    local pidfile="$1" name="$2" pids=""
    if [[ -s "$pidfile" ]] && kill -0 "$(cat "$pidfile")" 2>/dev/null; then
        pids="$(cat "$pidfile")"
    else
        # Fall back to exact process-name match (not a pattern over full command lines).
        pids="$(pgrep -x "$name" || true)"
    fi
    if [[ -z "$pids" ]]; then
        log "$name not running"
        rm -f "$pidfile"
        return 0
    fi
    log "stopping $name (pid $(echo $pids))"
    kill $pids 2>/dev/null || true
    for _ in $(seq 1 30); do
        local alive=0
        for p in $pids; do kill -0 "$p" 2>/dev/null && alive=1; done
        [[ "$alive" -eq 0 ]] && break
        sleep 0.5
    done
    for p in $pids; do kill -9 "$p" 2>/dev/null || true; done
    rm -f "$pidfile"
}

# Cancel remaining jobs first so slurmstepd/job processes do not linger.
if command -v scancel >/dev/null && scontrol ping 2>/dev/null | grep -q 'is UP'; then
    jobs="$(squeue -h -o %A 2>/dev/null | sort -u || true)"
    if [[ -n "$jobs" ]]; then
        log "cancelling jobs: $(echo $jobs)"
        scancel $jobs 2>/dev/null || true
        sleep 2
    fi
fi

stop_pidfile /run/slurmd.pid slurmd
stop_pidfile /run/slurmctld.pid slurmctld
stop_pidfile /run/munge/munged.pid munged
# Any job steps left behind by slurmd.
leftover="$(pgrep -x slurmstepd || true)"
if [[ -n "$leftover" ]]; then
    log "killing leftover slurmstepd: $(echo $leftover)"
    kill -9 $leftover 2>/dev/null || true
fi
log "done"
