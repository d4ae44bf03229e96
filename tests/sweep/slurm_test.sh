#!/usr/bin/env bash
# Runs a small sweep through a real single-node Slurm cluster started here (munged, slurmctld
# and slurmd with a generated slurm.conf in a scratch directory, on their own ports), and checks
# that its table is the one `tpsim sweep run` gives on this machine.
#
#   slurm_test.sh TPSIM SWEEP.toml WORK_DIR
#
# Needs root (the daemons run as root, as in CI) and Debian's slurm-wlm and munge (scripts/setup
# installs them); exits 77 (skipped) when not run as root.
set -euo pipefail
tpsim=$1 sweep=$2 work=$3

if [[ $(id -u) -ne 0 ]]; then
    echo "SKIPPED: starting munged, slurmctld and slurmd needs root (CI runs the tests as root)"
    exit 77
fi
for program in mungekey munged slurmctld slurmd sbatch sinfo; do
    command -v "$program" >/dev/null || {
        echo "FAIL: $program is not installed (scripts/setup installs slurm-wlm and munge)"
        exit 1
    }
done

scratch=$(mktemp -d /tmp/tpsim-slurm.XXXXXX)
pids=()
cleanup() {
    for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
    for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
    rm -rf "$scratch"
}
trap cleanup EXIT

# fail MESSAGE: the message, then the end of every daemon's log.
fail() {
    echo "FAIL: $1"
    for log in "$scratch"/*.log; do
        [[ -f $log ]] && { echo "--- $(basename "$log")"; tail -n 15 "$log"; }
    done
    exit 1
}

# start NAME COMMAND...: a daemon in the foreground of a background job; fails when it exits
# within a second.
start() {
    local name=$1
    shift
    "$@" >"$scratch/$name.out" 2>&1 &
    pids+=($!)
    sleep 1
    kill -0 "${pids[-1]}" 2>/dev/null || {
        cat "$scratch/$name.out"
        fail "$name did not start"
    }
}

mungekey --create --keyfile="$scratch/munge.key"
start munged munged --foreground --force --key-file="$scratch/munge.key" \
    --socket="$scratch/munge.socket" --pid-file="$scratch/munged.pid" \
    --log-file="$scratch/munged.log" --seed-file="$scratch/munged.seed"

# Ports of our own, so a Slurm already on this machine (or a second run of this test) is not
# disturbed.
port=$((20000 + RANDOM % 20000))
node=$(hostname -s)
mkdir -p "$scratch/state" "$scratch/spool"
# The node as slurmd sees it (CPUs, sockets, memory), so the controller accepts it as it is.
hardware=$(slurmd -C | head -n 1 | sed "s/^NodeName=[^ ]*/NodeName=$node/")
cat >"$scratch/slurm.conf" <<EOF
ClusterName=tpsimtest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$scratch/munge.socket
StateSaveLocation=$scratch/state
SlurmdSpoolDir=$scratch/spool
SlurmctldPidFile=$scratch/slurmctld.pid
SlurmdPidFile=$scratch/slurmd.pid
SlurmctldLogFile=$scratch/slurmctld.log
SlurmdLogFile=$scratch/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
$hardware NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$scratch/slurm.conf
start slurmctld slurmctld -D -c -f "$SLURM_CONF"
start slurmd slurmd -D -f "$SLURM_CONF" -N "$node"

# Wait until the node is idle (registered and ready for jobs), at most 60 s.
state=""
for _ in $(seq 60); do
    state=$(sinfo -h -N -n "$node" -o %t 2>/dev/null || true)
    [[ $state == idle ]] && break
    for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null || fail "a daemon exited"; done
    sleep 1
done
[[ $state == idle ]] || fail "the node is not idle after 60 s (state: '${state:-none}')"
echo "slurm node $node idle"

# The same sweep on Slurm and on this machine: the same table.
rm -rf "$work/slurm_results" "$work/local_results"
"$tpsim" sweep slurm "$sweep" -o "$scratch/results" --submit --wait --no-host-time >"$work/slurm.out" ||
    { cat "$work/slurm.out"; fail "tpsim sweep slurm --submit --wait failed"; }
cp -r "$scratch/results" "$work/slurm_results"
"$tpsim" sweep run "$sweep" -o "$work/local_results" -j 2 --no-host-time >/dev/null
tasks=$(ls "$work/slurm_results/logs" | grep -c '^slurm-[0-9]*_[0-9]*\.out$' || true)
jobs=$(grep -c '^| [0-9a-f]\{12\} |' "$work/slurm_results/table.md")
echo "array tasks: $tasks, jobs: $jobs"
cmp "$work/slurm_results/table.csv" "$work/local_results/table.csv" &&
    echo "slurm table identical to the local table"
