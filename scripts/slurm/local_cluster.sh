#!/usr/bin/env bash
# A real one-node Slurm cluster on this machine, in a folder of its own, for the tests and the
# throughput figures of `saltus sweep --slurm`. Nothing outside DIR is written: munged, slurmctld
# and slurmd take their key, sockets, state, spool, pid and log files from DIR, on ports of their
# own, so the machine's own Slurm (if any) is left alone.
#
#   local_cluster.sh start DIR [CPUS]   writes DIR/slurm.conf, starts munged, slurmctld, slurmd and
#                                       waits until the node is idle; prints `export SLURM_CONF=...`
#   local_cluster.sh stop DIR           stops the three daemons (slurmd, slurmctld, munged)
#
# Clients (sbatch, squeue, scancel, scontrol, saltus sweep --slurm) find the cluster through
# SLURM_CONF=DIR/slurm.conf. Needs root (slurmd starts jobs as their user) and Debian's slurm-wlm
# and munge (scripts/packages.txt). Exit status 2: cannot start here (not root, daemons missing).
set -euo pipefail

usage() { echo "usage: $0 start|stop DIR [CPUS]" >&2; exit 64; }
(($# >= 2)) || usage
action="$1"
dir="$(mkdir -p "$2" && cd "$2" && pwd)"
cpus="${3:-$(nproc)}"

stop_daemon() {  # pid file, name
  local pid_file="$1" name="$2" pid
  [[ -s "$pid_file" ]] || return 0
  pid="$(cat "$pid_file")"
  if kill -0 "$pid" 2>/dev/null; then
    kill -TERM "$pid" 2>/dev/null || true
    for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -0 "$pid" 2>/dev/null && kill -KILL "$pid" 2>/dev/null || true
  fi
  rm -f "$pid_file"
}

if [[ "$action" == stop ]]; then
  stop_daemon "$dir/slurmd.pid" slurmd
  stop_daemon "$dir/slurmctld.pid" slurmctld
  stop_daemon "$dir/munged.pid" munged
  exit 0
fi
[[ "$action" == start ]] || usage

if ((EUID != 0)); then
  echo "local_cluster: not root: slurmd must run as root to start jobs as their user" >&2
  exit 2
fi
for program in munged slurmctld slurmd sbatch; do
  if ! command -v "$program" >/dev/null && [[ ! -x "/usr/sbin/$program" ]]; then
    echo "local_cluster: $program is not installed (bash scripts/setup.sh installs slurm-wlm and munge)" >&2
    exit 2
  fi
done
export PATH="$PATH:/usr/sbin"

# Free TCP ports for the controller and the node daemon.
free_port() {
  python3 - <<'PY'
import socket
s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1]); s.close()
PY
}
ctld_port="$(free_port)"
slurmd_port="$(free_port)"
while [[ "$slurmd_port" == "$ctld_port" ]]; do slurmd_port="$(free_port)"; done

host="$(hostname -s)"
mkdir -p "$dir/munge" "$dir/state" "$dir/spool"
chmod 0700 "$dir/munge"
# munged checks that no one else can write to its key, socket and log folders.
if [[ ! -s "$dir/munge/munge.key" ]]; then
  dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
  chmod 0400 "$dir/munge/munge.key"
fi
memory_mb="$(awk '/MemTotal/ { print int($2 / 1024 * 0.9) }' /proc/meminfo)"
memory_per_cpu_mb=$((memory_mb / cpus))

cat >"$dir/slurm.conf" <<CONF
# A one-node Slurm cluster for Saltus' tests (scripts/slurm/local_cluster.sh).
ClusterName=saltus-local
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool/%n
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
# No cgroups: processes are tracked through /proc, so containers without a cgroup mount work.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
# A task without --mem gets its share of the node, so every core can run one.
DefMemPerCPU=$memory_per_cpu_mb
ReturnToService=2
# Finished jobs stay visible to scontrol for an hour (there is no accounting database).
MinJobAge=3600
# A cancelled or timed-out task gets SIGTERM, then SIGKILL 5 s later.
KillWait=5
SchedulerParameters=sched_interval=1
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory_mb State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$dir/slurm.conf"

munged --force --socket="$dir/munge/munge.socket" --key-file="$dir/munge/munge.key" \
       --pid-file="$dir/munged.pid" --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed"
slurmctld -f "$dir/slurm.conf"
slurmd -f "$dir/slurm.conf" -N "$host"

# Ready when the node answers as idle.
for _ in $(seq 1 300); do
  if sinfo -h -N -o '%T' 2>/dev/null | grep -qx idle; then
    echo "export SLURM_CONF=$dir/slurm.conf"
    exit 0
  fi
  sleep 0.1
done
echo "local_cluster: the node did not become idle within 30 s; the last lines of the logs:" >&2
tail -n 5 "$dir/slurmctld.log" "$dir/slurmd.log" "$dir/munge/munged.log" >&2 || true
"$0" stop "$dir"
exit 1
