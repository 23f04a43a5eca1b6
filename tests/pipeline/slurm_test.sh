#!/usr/bin/env bash
# pipeline/Makefile under a real scheduler: brings up a one-node Slurm
# cluster on this machine (Debian's slurm-wlm and munge; its configuration,
# state and logs in a temporary folder, stopped at the end), runs a tiny
# dataset run with every stage a Slurm job (LAUNCH="srun ..."), and checks
# that its outputs equal those of the same run made locally, and that Slurm
# ran one job per stage. Skipped (exit 77) with the reason where Slurm is not
# installed or cannot start (it needs root to run its daemons as here).
# Usage: slurm_test.sh BIN_DIR
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh" "$1"
for tool in munged slurmctld slurmd srun sinfo; do
  command -v "$tool" > /dev/null || skip "$tool not found (apt-get install slurm-wlm munge)"
done
[ "$(id -u)" -eq 0 ] || skip "the test runs Slurm's daemons as root"

# ------------------------------------------------------ a one-node cluster
s="$tmp/slurm"
mkdir -p "$s/state" "$s/spool"
stop_cluster() {
  local p pid
  for p in slurmd slurmctld munged; do
    [ -f "$s/$p.pid" ] || continue
    pid=$(cat "$s/$p.pid")
    kill "$pid" 2> /dev/null
    for ((i = 0; i < 50; i++)); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
  done
  return 0
}
trap 'stop_cluster; rm -rf "$tmp"' EXIT
head -c 1024 /dev/urandom > "$s/munge.key"
chmod 400 "$s/munge.key"
munged --force --key-file="$s/munge.key" --socket="$s/munge.sock" --log-file="$s/munged.log" \
  --pid-file="$s/munged.pid" --seed-file="$s/munged.seed" || skip "munged did not start"
# Two free ports for the controller and the node daemon.
port=$((20000 + RANDOM % 20000))
while ss -ltn | grep -q ":$port \|:$((port + 1)) "; do port=$((port + 2)); done
host=$(hostname -s)
memory_mb=$(($(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 1024))
cat > "$s/slurm.conf" << EOF
ClusterName=op2gstest
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$s/munge.sock
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$s/state
SlurmdSpoolDir=$s/spool
SlurmctldPidFile=$s/slurmctld.pid
SlurmdPidFile=$s/slurmd.pid
SlurmctldLogFile=$s/slurmctld.log
SlurmdLogFile=$s/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
NodeName=$host CPUs=$(nproc) RealMemory=$memory_mb State=UNKNOWN
PartitionName=op2gs Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$s/slurm.conf"
slurmctld -f "$SLURM_CONF" || skip "slurmctld did not start (see $s/slurmctld.log)"
slurmd -f "$SLURM_CONF" || skip "slurmd did not start"
for ((i = 0; i < 100; i++)); do
  [ "$(sinfo -h -o %t 2> /dev/null)" = idle ] && break
  sleep 0.2
done
[ "$(sinfo -h -o %t 2> /dev/null)" = idle ] || { tail -5 "$s/slurmd.log"; skip "the node did not come up"; }
echo "-- a one-node Slurm cluster is up: $(sinfo -h -o '%P %D node(s), %c CPUs, %m MB')"

# -------------------------------------------- the same run, local and Slurm
tiny_lerf_run "$tmp/work"
mk "${run[@]}" > "$tmp/local.log" 2>&1 || { tail -20 "$tmp/local.log"; fail "the local run failed"; }
local_outputs=$(work_outputs "$tmp/work")
rm -rf "$tmp/work"
launch="srun --quiet --ntasks=1 --cpus-per-task=$(nproc) --mem=2000 --time=10"
mk "${run[@]}" LAUNCH="$launch" > "$tmp/slurm.log" 2>&1 ||
  { tail -20 "$tmp/slurm.log"; tail -5 "$s/slurmctld.log"; fail "the run under Slurm failed"; }
[ "$(work_outputs "$tmp/work")" = "$local_outputs" ] || {
  diff <(echo "$local_outputs") <(work_outputs "$tmp/work") | head -5 || true
  fail "the outputs under Slurm differ from the local run's"; }
stages=$(grep -c '^== .*: [a-z-]*$' "$tmp/slurm.log")
jobs=$(grep -c '_job_complete: JobId=[0-9]* done' "$s/slurmctld.log")
[ "$jobs" -eq "$stages" ] || fail "$stages stages ran, but Slurm ran $jobs jobs"
echo "-- $stages stages ran as $jobs Slurm jobs; outputs identical to the local run"
echo "PASS"
