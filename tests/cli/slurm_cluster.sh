# SPDX-License-Identifier: Apache-2.0
# A one-node Slurm cluster for a test, sourced: start_cluster starts munged, slurmctld and
# slurmd with their config, state, spool, pid and log files in a temporary directory of
# their own (which the munge user can reach) and exports SLURM_CONF; stop_cluster stops
# them by their pids and removes the directory. It needs root (slurmd starts jobs as
# their users) and no systemd. On failure start_cluster prints why and returns 1.

cluster_dir=""

# A TCP port nothing listens on, from `from` up.
free_port() {
  local port=$1
  while ss -ltnH "sport = :$port" 2>/dev/null | grep -q .; do port=$((port + 1)); done
  echo "$port"
}

start_cluster() {
  local why=""
  [ "$(id -u)" = 0 ] || why="not root (slurmd must start jobs as their users)"
  for p in munged slurmctld slurmd sbatch scontrol squeue scancel; do
    [ -n "$why" ] || command -v "$p" >/dev/null || why="$p is not installed (.ci/install-deps)"
  done
  if [ -n "$why" ]; then
    echo "no Slurm cluster: $why"
    return 1
  fi
  cluster_dir=$(mktemp -d /tmp/sweepers-slurm.XXXXXX)
  local d=$cluster_dir
  mkdir -p "$d/state" "$d/spool" "$d/log"
  chmod 755 "$d"
  # munged runs as its own user, with its socket and key in a directory of its own.
  install -d -o munge -g munge -m 755 "$d/munge"
  install -o munge -g munge -m 400 /etc/munge/munge.key "$d/munge/key"
  su -s /bin/sh munge -c "munged --socket=$d/munge/socket --key-file=$d/munge/key \
    --pid-file=$d/munge/pid --log-file=$d/munge/log --seed-file=$d/munge/seed" ||
    { echo "no Slurm cluster: munged did not start: $(tail -1 "$d/munge/log")"; return 1; }
  local ctld_port node_port cpus memory
  ctld_port=$(free_port $((17000 + $$ % 2000 * 2)))
  node_port=$(free_port $((ctld_port + 1)))
  cpus=$(nproc)
  memory=$(($(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo) * 3 / 4))
  cat >"$d/slurm.conf" <<EOF
ClusterName=sweepers-test
SlurmctldHost=localhost
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$node_port
AuthType=auth/munge
AuthInfo=socket=$d/munge/socket
CredType=cred/munge
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmctldLogFile=$d/log/slurmctld.log
SlurmdLogFile=$d/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
MinJobAge=600
NodeName=localhost CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF=$d/slurm.conf
  slurmctld -f "$SLURM_CONF" && slurmd -f "$SLURM_CONF" ||
    { echo "no Slurm cluster: its daemons did not start"; return 1; }
  for _ in $(seq 1 60); do
    [ "$(sinfo -h -o %T 2>/dev/null)" = idle ] && return 0
    sleep 0.5
  done
  echo "no Slurm cluster: the node did not come up: $(tail -3 "$d/log/slurmd.log")"
  return 1
}

stop_cluster() {
  [ -n "$cluster_dir" ] || return 0
  local pids=""
  for f in slurmd.pid slurmctld.pid munge/pid; do
    [ -f "$cluster_dir/$f" ] && pids="$pids $(cat "$cluster_dir/$f")"
  done
  if [ -n "$pids" ]; then
    # shellcheck disable=SC2086
    kill $pids 2>/dev/null || true
    for _ in $(seq 1 50); do
      # shellcheck disable=SC2086
      kill -0 $pids 2>/dev/null || break
      sleep 0.1
    done
    # shellcheck disable=SC2086
    kill -9 $pids 2>/dev/null || true
  fi
  rm -rf "$cluster_dir"
}
