#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for the tests labelled `slurm` and for trying
# `arview map --engine slurm`: starts munged, slurmctld and slurmd without systemd, from
# tests/support/slurm/slurm.conf.in, and waits until sinfo shows the node idle; `stop` stops
# them. Everything (configuration, state, logs, munge's socket) lives in $ARVIEW_SLURM_DIR
# (default /tmp/arview-slurm-<uid>). The node offers $ARVIEW_SLURM_CPUS CPUs (default: all of
# this machine's, nproc): fewer make it stand for a smaller node (scripts/venue-scale.sh).
#
#   scripts/slurm-local.sh start    # then: export SLURM_CONF=$ARVIEW_SLURM_DIR/slurm.conf
#   scripts/slurm-local.sh stop
#   scripts/slurm-local.sh status   # exit status 0 when both daemons run
#   scripts/slurm-local.sh conf     # prints the slurm.conf path (for SLURM_CONF)
#   scripts/slurm-local.sh kill-node   # the node dies: slurmd killed (SIGKILL); slurmctld marks
#                                      # it down after SlurmdTimeout (10 s here)
#   scripts/slurm-local.sh start-node  # the node back: slurmd started again (ReturnToService=2)
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${ARVIEW_SLURM_DIR:-/tmp/arview-slurm-$(id -u)}"
conf="$dir/slurm.conf"
cpus="${ARVIEW_SLURM_CPUS:-$(nproc)}"
export SLURM_CONF="$conf"

die() { echo "slurm-local: $*" >&2; exit 1; }

pid_alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

stop_daemon() {  # pid file, name
  if pid_alive "$1"; then
    local pid
    pid="$(cat "$1")"
    kill "$pid"
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -0 "$pid" 2>/dev/null && kill -9 "$pid" 2>/dev/null || true
  fi
  rm -f "$1"
}

stop() {
  stop_daemon "$dir/slurmd.pid" slurmd
  stop_daemon "$dir/slurmctld.pid" slurmctld
  stop_daemon "$dir/munge/munged.pid" munged
  echo "slurm-local: stopped"
}

write_conf() {
  mkdir -p "$dir/ctld" "$dir/slurmd" "$dir/munge"
  chmod 700 "$dir/munge"
  sed -e "s|@HOST@|$(hostname -s)|g" -e "s|@USER@|$(id -un)|g" -e "s|@STATE@|$dir|g" \
      -e "s|@CPUS@|$cpus|g" -e "s|@CTLD_PORT@|${ARVIEW_SLURMCTLD_PORT:-6817}|g" \
      -e "s|@SLURMD_PORT@|${ARVIEW_SLURMD_PORT:-6818}|g" \
      tests/support/slurm/slurm.conf.in > "$conf"
}

start() {
  for tool in munged slurmctld slurmd sinfo; do
    command -v "$tool" >/dev/null || [ -x "/usr/sbin/$tool" ] ||
      die "$tool not found (bash scripts/install-deps.sh installs munge, slurmctld, slurmd, slurm-client)"
  done
  [[ "$cpus" =~ ^[0-9]+$ ]] && [ "$cpus" -ge 1 ] && [ "$cpus" -le "$(nproc)" ] ||
    die "ARVIEW_SLURM_CPUS=$cpus: give 1 to $(nproc) (this machine's CPUs)"
  [ "$(id -u)" -eq 0 ] || die "slurmd must run as root (it starts jobs as their user)"
  if pid_alive "$dir/slurmctld.pid" && pid_alive "$dir/slurmd.pid"; then
    echo "slurm-local: already running ($conf)"
    return 0
  fi
  stop >/dev/null
  write_conf
  local key=/etc/munge/munge.key
  [ -r "$key" ] || die "$key missing (the munge package creates it; or: mungekey --create)"
  PATH="/usr/sbin:$PATH"
  munged --force --socket="$dir/munge/munge.socket" --pid-file="$dir/munge/munged.pid" \
         --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed" --key-file="$key" ||
    die "munged did not start: see $dir/munge/munged.log"
  slurmctld -f "$conf" || die "slurmctld did not start: see $dir/slurmctld.log"
  slurmd -f "$conf" || die "slurmd did not start: see $dir/slurmd.log"
  local state=""
  for _ in $(seq 60); do
    state="$(sinfo -h -N -o '%T' 2>/dev/null | head -1)"
    [ "$state" = idle ] && break
    sleep 0.5
  done
  if [ "$state" != idle ]; then
    stop >/dev/null
    die "the node did not become idle in 30 s (state '${state:-none}'): see $dir/slurmctld.log and $dir/slurmd.log"
  fi
  echo "slurm-local: running, one node '$(hostname -s)' with $cpus CPUs; export SLURM_CONF=$conf"
}

kill_node() {
  pid_alive "$dir/slurmd.pid" || die "slurmd is not running"
  kill -9 "$(cat "$dir/slurmd.pid")"
  echo "slurm-local: slurmd killed"
}

start_node() {
  pid_alive "$dir/slurmctld.pid" || die "slurmctld is not running: scripts/slurm-local.sh start"
  if pid_alive "$dir/slurmd.pid"; then echo "slurm-local: slurmd already running"; return 0; fi
  PATH="/usr/sbin:$PATH"
  slurmd -f "$conf" || die "slurmd did not start: see $dir/slurmd.log"
  echo "slurm-local: slurmd started"
}

case "${1:-}" in
  start) start ;;
  kill-node) kill_node ;;
  start-node) start_node ;;
  stop) stop ;;
  status) pid_alive "$dir/slurmctld.pid" && pid_alive "$dir/slurmd.pid" && echo "slurm-local: running ($conf)" ;;
  conf) echo "$conf" ;;
  *) echo "usage: scripts/slurm-local.sh start|stop|status|conf|kill-node|start-node" >&2; exit 2 ;;
esac
