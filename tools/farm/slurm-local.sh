#!/bin/sh
# A single-node Slurm on this machine, for tests and trying `shellmpm batch submit`:
# munged, slurmctld and slurmd as root without systemd, their configuration, state and logs
# under ROOT, two partitions (low, and high, which preempts low by requeueing it).
#   tools/farm/slurm-local.sh start ROOT [CPUS [PORT]]
#       prints `export SLURM_CONF=ROOT/slurm.conf`; PORT (default 6817) and PORT+1 are the
#       controller's and the node daemon's (two clusters at once need their own)
#   tools/farm/slurm-local.sh stop ROOT           cancels every job, stops the daemons by PID
# Needs Debian 12's slurm-wlm and munge (tools/install-deps.sh). The recipe and its pitfalls:
# docs/farm.md, "A single-node Slurm".
set -eu
cmd=${1:-}
root=${2:-}
[ -n "$cmd" ] && [ -n "$root" ] || { echo "usage: $0 start|stop ROOT [CPUS [PORT]]" >&2; exit 2; }
conf="$root/slurm.conf"

stop_pid() {  # stop_pid PIDFILE: TERM, wait up to 10 s, then KILL
  [ -f "$1" ] || return 0
  pid=$(cat "$1")
  [ -n "$pid" ] || return 0
  kill -TERM "$pid" 2>/dev/null || return 0
  i=0
  while kill -0 "$pid" 2>/dev/null && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
  kill -KILL "$pid" 2>/dev/null || true
}

case "$cmd" in
start)
  cpus=${3:-$(nproc)}
  port=${4:-6817}
  host=$(hostname -s)
  for tool in munged mungekey slurmctld slurmd sinfo runuser; do
    command -v "$tool" >/dev/null 2>&1 || [ -x "/usr/sbin/$tool" ] ||
      { echo "slurm-local: $tool is missing (sh tools/install-deps.sh)" >&2; exit 3; }
  done
  PATH="$PATH:/usr/sbin:/sbin"
  mkdir -p "$root/state" "$root/spool" "$root/log" "$root/run" "$root/munge"
  chmod 755 "$root"
  chown munge:munge "$root/munge"
  chmod 711 "$root/munge"
  [ -f "$root/munge/munge.key" ] ||
    runuser -u munge -- mungekey --create --keyfile="$root/munge/munge.key"
  runuser -u munge -- munged --socket="$root/munge/munge.socket.2" \
    --key-file="$root/munge/munge.key" --pid-file="$root/munge/munged.pid" \
    --log-file="$root/munge/munged.log" --seed-file="$root/munge/munged.seed"
  cat > "$conf" <<CONF
# Single-node Slurm for tests: no systemd, no cgroups, root only (tools/farm/slurm-local.sh).
ClusterName=shellmpm
SlurmctldHost=localhost
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
# cred_expire also sets how long a requeued job waits before it may start (default 120 s).
AuthInfo=socket=$root/munge/munge.socket.2,cred_expire=10
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
SwitchType=switch/none
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$root/log/jobcomp.txt
StateSaveLocation=$root/state
SlurmdSpoolDir=$root/spool
SlurmctldPidFile=$root/run/slurmctld.pid
SlurmdPidFile=$root/run/slurmd.pid
SlurmctldLogFile=$root/log/slurmctld.log
SlurmdLogFile=$root/log/slurmd.log
ReturnToService=2
KillWait=10
MinJobAge=600
InactiveLimit=0
SchedulerParameters=sched_interval=2
# Preemption: jobs in "high" requeue jobs in "low"; the --signal is sent at preemption.
PreemptType=preempt/partition_prio
PreemptMode=REQUEUE
SlurmctldParameters=preempt_send_user_signal
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=1000 State=UNKNOWN
PartitionName=low  Nodes=ALL Default=YES MaxTime=INFINITE State=UP PriorityTier=1 PreemptMode=REQUEUE GraceTime=20
PartitionName=high Nodes=ALL Default=NO  MaxTime=INFINITE State=UP PriorityTier=2 PreemptMode=OFF
CONF
  export SLURM_CONF="$conf"
  setsid slurmctld -D -f "$conf" >"$root/log/slurmctld.out" 2>&1 </dev/null &
  setsid slurmd -D -f "$conf" >"$root/log/slurmd.out" 2>&1 </dev/null &
  i=0
  until [ "$(sinfo -h -o %T 2>/dev/null | head -n 1)" = idle ]; do
    i=$((i + 1))
    if [ $i -gt 300 ]; then
      echo "slurm-local: the node did not come up in 30 s; logs in $root/log" >&2
      exit 1
    fi
    sleep 0.1
  done
  echo "export SLURM_CONF=$conf"
  ;;
stop)
  if [ -f "$conf" ]; then SLURM_CONF="$conf" scancel --full --quiet --partition=low,high 2>/dev/null || true; fi
  stop_pid "$root/run/slurmd.pid"
  stop_pid "$root/run/slurmctld.pid"
  stop_pid "$root/munge/munged.pid"
  ;;
*)
  echo "usage: $0 start|stop ROOT [CPUS [PORT]]" >&2
  exit 2
  ;;
esac
