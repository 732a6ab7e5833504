#!/usr/bin/env bash
# Tries experiments/slurm/run-array.sh on a real Slurm: stands up a throwaway one-node
# cluster on this machine (Debian or Ubuntu, as root; installs slurm-wlm and munge if they
# are missing) and checks, on the shipped cbox experiment given a small passes budget:
#
#  1. the documented command, with one array task cancelled by hand: the report marks the run
#     incomplete and names the missing cell and its log; the same command again queues only
#     that cell, keeps the others' files untouched, and the report's rows then equal a
#     single-machine run's (every column but the times);
#  2. a prepare job that fails: Slurm cancels the array instead of leaving it pending, and the
#     report job says which job failed and shows the end of its log.
#
#   experiments/slurm/test-local-slurm.sh          # MLTBENCH=... as for run-array.sh
#
# Everything it writes goes to a new temporary folder: its own slurm.conf, munge key and
# socket, state, spool and logs, on ports of its own (SLURM_TEST_PORT, default 16817, and
# the next one). It never reads or writes /etc/slurm or /etc/munge, so an existing Slurm
# installation, slurm.conf or munge key is left as it is. The daemons it started are stopped
# when it ends, also on failure. Exit code 0 when every check passed.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
say() { echo "== $*"; }
fail() {
    echo "FAILED: $*" >&2
    exit 1
}

[[ "$(id -u)" == 0 ]] || fail "run as root: it starts slurmctld, slurmd and munged"
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    command -v apt-get >/dev/null || fail "slurm-wlm and munge are missing and there is no apt-get"
    say "installing slurm-wlm and munge"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi
port="${SLURM_TEST_PORT:-16817}"
for p in "$port" "$((port + 1))"; do
    if (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; then
        fail "port $p is in use: set SLURM_TEST_PORT to a free pair of ports"
    fi
done

work="$(mktemp -d /tmp/mltbench-slurm-test.XXXXXX)"
chmod 755 "$work" # munged wants its socket reachable by every user
pids=()
stop_daemons() {
    local pid
    for pid in "${pids[@]}"; do
        kill "$pid" 2>/dev/null || true
    done
    for pid in "${pids[@]}"; do
        while kill -0 "$pid" 2>/dev/null; do sleep 0.2; done
    done
    ((${#pids[@]})) && say "stopped the daemons this script started (pids ${pids[*]}); files in $work"
    return 0
}
trap stop_daemons EXIT

# A munged of our own: its own key, socket and files.
mkdir -p "$work/munge"
chmod 755 "$work/munge"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 600 "$work/munge/munge.key"
munged --socket="$work/munge/socket" --key-file="$work/munge/munge.key" \
    --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" \
    --seed-file="$work/munge/munged.seed"
pids+=("$(cat "$work/munge/munged.pid")")

# slurm.conf for one node, this machine, as its hardware is (slurmd -C).
host="$(hostname -s)"
node="$(slurmd -C | head -n 1 | sed 's/ UpTime=.*//')"
mkdir -p "$work/state" "$work/spool"
export SLURM_CONF="$work/slurm.conf"
cat >"$SLURM_CONF" <<EOF
ClusterName=mltbench-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$work/munge/socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MinJobAge=3600
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
say "slurm.conf ($SLURM_CONF):"
sed 's/^/    /' "$SLURM_CONF"
slurmctld -f "$SLURM_CONF"
for _ in $(seq 50); do [[ -s "$work/slurmctld.pid" ]] && break; sleep 0.2; done
pids+=("$(cat "$work/slurmctld.pid")")
slurmd -f "$SLURM_CONF"
for _ in $(seq 50); do [[ -s "$work/slurmd.pid" ]] && break; sleep 0.2; done
pids+=("$(cat "$work/slurmd.pid")")
for _ in $(seq 60); do
    state="$(sinfo -h -o %T 2>/dev/null || true)"
    [[ "$state" == idle ]] && break
    sleep 1
done
[[ "$state" == idle ]] || fail "the node did not come up ($state): see $work/slurmctld.log, $work/slurmd.log"
say "Slurm $(sinfo -V | cut -d ' ' -f 2) is up: $(sinfo -h -o '%P %D node, %c CPUs, %T')"

# Waits until none of the jobs is pending or running (10 minutes at most: a job that stays
# pending is a failure, not a wait forever).
wait_jobs() {
    local ids="$1" left
    for _ in $(seq 600); do
        left="$(squeue -h -j "$ids" -o %i 2>/dev/null || true)"
        [[ -z "$left" ]] && return 0
        sleep 1
    done
    squeue -j "$ids" -o '%i %j %T %r' || true
    fail "jobs $ids still queued after 10 minutes"
}
# What Slurm says of each job: name, state, reason, exit code (kept for MinJobAge; an array
# task cancelled while pending leaves no record of its own).
job_states() {
    local id line
    for id in "$@"; do
        if line="$(scontrol -o show job "$id" 2>/dev/null | head -n 1)" && [[ -n "$line" ]]; then
            echo "    $id: $(grep -o 'JobName=[^ ]*\|JobState=[^ ]*\|Reason=[^ ]*\|ExitCode=[^ ]*' <<<"$line" |
                paste -s -d ' ')"
        else
            echo "    $id: no record (an array task cancelled before it started)"
        fi
    done
}
# "submitted: prepare P, N of M cells as array A (...), report R" -> the numbers P, A, R.
ids_of() {
    sed -n 's/^submitted: prepare \([0-9]*\), .* as array \([0-9]*\) .*, report \([0-9]*\)$/\1 \2 \3/p' <<<"$1"
}
# metrics.csv without its seconds column; summary.csv without the columns made from times
# (seconds, slope against time and its error, efficiency and its interval).
untimed() {
    cut -d , -f 1-3,5- "$1/metrics.csv"
    cut -d , -f 1-3,5-14,17-18,22- "$1/summary.csv"
}

# The shipped cbox experiment with a passes budget (reproducible bit for bit) and a short
# reference; its scene path made absolute, as the copy lives elsewhere.
mkdir -p "$work/experiments"
spec="$work/experiments/cbox-passes.toml"
sed -e "s|^scene = \"scenes/|scene = \"$repo/experiments/scenes/|" \
    -e 's/^budget = { seconds = [0-9.]* }/budget = { passes = 16 }/' \
    -e 's/^budget = { passes = 8192 }/budget = { passes = 512 }/' \
    "$repo/experiments/cbox.toml" >"$spec"
grep -q 'budget = { passes = 16 }' "$spec" && grep -q 'budget = { passes = 512 }' "$spec" ||
    fail "experiments/cbox.toml changed: update the budgets this script rewrites"

cd "$repo"
results="$work/slurm results" # a space in the path, as some users have
site=(--sbatch-arg=--mem=500M --sbatch-arg=--time=00:20:00)
command=("$here/run-array.sh" "$spec" --results "$results" --threads 1 "${site[@]}")
say "Slurm: ${command[*]}  (then scancel of array task 3)"
out="$(CPUS_PER_CELL=1 "${command[@]}")"
echo "$out" | sed 's/^/    /'
read -r prepare array report <<<"$(ids_of "$out")"
[[ -n "$report" ]] || fail "could not read the job ids"
scancel "${array}_3"
wait_jobs "$prepare,$array,$report"
job_states "$prepare" "${array}_3" "$report"
report_log="$results/slurm-logs/cbox-passes-report-$report.out"
say "report job's log ($report_log):"
sed 's/^/    /' "$report_log"
grep -q 'cell 3 (pt (rr from 1) run 0) has no results' "$report_log" ||
    fail "the report log does not name the cancelled cell 3"
grep -q 'Incomplete.*pt (rr from 1) run 0' "$results/cbox-passes/README.md" ||
    fail "the README does not say the run is incomplete"

# The single-machine run, with the most portable build there is (the Slurm jobs here run the
# highest level this CPU supports): the same rows also say that the levels agree.
bins="${MLTBENCH:-${CARGO_TARGET_DIR:-$repo/target}/slurm}"
single_bin="$bins"
[[ -x "$bins/x86-64-v2/release/mltbench" ]] && single_bin="$bins/x86-64-v2/release/mltbench"
single_bin="$("$here/job.sh" pick "$single_bin")"
say "single machine: mltbench run $spec (with $single_bin)"
"$single_bin" run "$spec" --results "$work/single" --threads 2 2>&1 | tail -n 12

stamps() { stat -c '%n %Y.%y' "$results"/cbox-passes/cells/* "$results"/cbox-passes/images/*.exr | grep -v 'rr_from_1_-run0'; }
before="$(stamps)"
sleep 1

say "Slurm, the same command again: only the cancelled cell is queued"
out="$(CPUS_PER_CELL=1 "${command[@]}")"
echo "$out" | sed 's/^/    /'
grep -q '1 of 12 cells as array [0-9]* (3)' <<<"$out" || fail "expected only cell 3 to be queued"
read -r prepare array report <<<"$(ids_of "$out")"
wait_jobs "$prepare,$array,$report"
job_states "$prepare" "${array}_3" "$report"
sed 's/^/    /' "$results/slurm-logs/cbox-passes-report-$report.out"
[[ "$(stamps)" == "$before" ]] || fail "the resubmission rewrote cells that were complete"
grep -q '"missing_cells": \[\]' "$results/cbox-passes/summary.json" || fail "cells still missing"
if ! diff <(untimed "$work/single/cbox-passes") <(untimed "$results/cbox-passes") >"$work/diff.txt"; then
    head -n 20 "$work/diff.txt"
    fail "the Slurm report's rows differ from the single machine's"
fi
say "OK: metrics.csv ($(($(wc -l <"$results/cbox-passes/metrics.csv") - 1)) rows) and summary.csv" \
    "equal the single machine's but for the time columns; complete cells were kept as they were"

say "Slurm, a prepare job that fails (a region off the film)"
bad="$work/experiments/cbox-bad.toml"
{
    cat "$spec"
    printf '\n[[region]]\nlabel = "off the film"\nx = 500\ny = 0\nwidth = 8\nheight = 8\n'
} >"$bad"
out="$(CPUS_PER_CELL=1 "$here/run-array.sh" "$bad" --results "$results" "${site[@]}")"
echo "$out" | sed 's/^/    /'
read -r prepare array report <<<"$(ids_of "$out")"
wait_jobs "$prepare,$array,$report"
job_states "$prepare" "${array}_0" "$report"
scontrol -o show job "$array" | grep -q 'JobState=CANCELLED' || fail "the array was not cancelled"
ls "$results/slurm-logs/cbox-bad-cell-${array}_"* >/dev/null 2>&1 && fail "array tasks ran"
report_log="$results/slurm-logs/cbox-bad-report-$report.out"
say "report job's log ($report_log):"
sed 's/^/    /' "$report_log"
grep -q "the prepare job $prepare did not succeed" "$report_log" &&
    grep -q "cbox-bad-prepare-$prepare.out" "$report_log" &&
    grep -q 'off the film' "$report_log" || fail "the report log does not say why"
say "OK: the failed prepare job cancelled the array and the report job said why"
say "all checks passed"
