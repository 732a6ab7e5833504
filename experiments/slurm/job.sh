#!/usr/bin/env bash
# One job of a run-array.sh submission (sbatch copies this script, so it relies on nothing
# beside it). BIN is an mltbench binary or a folder of builds, LEVEL/release/mltbench, one
# per x86-64 level: each job runs the highest level its node's CPU supports. PREFIX is the
# logs' folder and the experiment's name: PREFIX-prepare-JOBID.out and so on.
#
#   job.sh pick BIN                               the binary for this machine
#   job.sh prepare BIN PREFIX -- RUN_ARGS...      mltbench RUN_ARGS; on success, PREFIX-prepare-JOBID.ok
#   job.sh cell BIN -- RUN_ARGS...                mltbench RUN_ARGS --cell SLURM_ARRAY_TASK_ID
#   job.sh report BIN PREFIX PREPARE ARRAY -- REPORT_ARGS...
#                                                 checks that job PREPARE succeeded, then
#                                                 mltbench REPORT_ARGS, then names the logs of
#                                                 the cells of array ARRAY that left no results
set -euo pipefail

fail() {
    echo "mltbench job: error: $*" >&2
    exit 1
}

# True when this CPU has every flag of x86-64 level $1 (as /proc/cpuinfo names them).
has_level() {
    local flags need f
    flags=" $(grep -m 1 '^flags' /proc/cpuinfo 2>/dev/null | cut -d : -f 2) "
    case "$1" in
    x86-64-v2) need="cx16 lahf_lm popcnt pni sse4_1 sse4_2 ssse3" ;;
    x86-64-v3) need="cx16 lahf_lm popcnt pni sse4_1 sse4_2 ssse3 avx avx2 bmi1 bmi2 f16c fma abm movbe xsave" ;;
    x86-64-v4) need="cx16 lahf_lm popcnt pni sse4_1 sse4_2 ssse3 avx avx2 bmi1 bmi2 f16c fma abm movbe xsave avx512f avx512bw avx512cd avx512dq avx512vl" ;;
    *) return 1 ;;
    esac
    for f in $need; do
        [[ "$flags" == *" $f "* ]] || return 1
    done
}

# The binary to run here: BIN itself, or the highest level of its builds this CPU supports.
pick() {
    local level
    if [[ ! -d "$1" ]]; then
        [[ -x "$1" ]] || fail "$1 is not an executable mltbench"
        echo "$1"
        return
    fi
    for level in x86-64-v4 x86-64-v3 x86-64-v2; do
        if [[ -x "$1/$level/release/mltbench" ]] && has_level "$level"; then
            echo "$1/$level/release/mltbench"
            return
        fi
    done
    if [[ -x "$1/x86-64/release/mltbench" ]]; then
        echo "$1/x86-64/release/mltbench"
        return
    fi
    fail "no build in $1 runs on this CPU ($(hostname)): build one for a level it supports"
}

# Everything up to "--" is this script's; the rest goes to mltbench.
kind="${1:?usage: job.sh pick|prepare|cell|report BIN ...}"
bin="${2:?job.sh: BIN missing}"
shift 2
if [[ "$kind" == pick ]]; then
    pick "$bin"
    exit 0
fi
own=()
while (($#)) && [[ "$1" != -- ]]; do
    own+=("$1")
    shift
done
(($#)) || fail "job.sh $kind: '--' missing"
shift
mltbench="$(pick "$bin")"
echo "mltbench job: $kind ${SLURM_ARRAY_TASK_ID:+$SLURM_ARRAY_TASK_ID }on $(hostname) with $mltbench" >&2

case "$kind" in
prepare)
    "$mltbench" "$@"
    touch "${own[0]}-prepare-${SLURM_JOB_ID:?not in a Slurm job}.ok"
    ;;
cell)
    exec "$mltbench" "$@" --cell "${SLURM_ARRAY_TASK_ID:?not in a Slurm array task}"
    ;;
report)
    prefix="${own[0]}"
    prepare="${own[1]:-}"
    array="${own[2]:-}"
    if [[ -n "$prepare" && ! -e "$prefix-prepare-$prepare.ok" ]]; then
        log="$prefix-prepare-$prepare.out"
        {
            echo "mltbench job: error: the prepare job $prepare did not succeed (it failed," \
                "was cancelled or ran out of time), so Slurm cancelled the cell array" \
                "${array:-(none)} (--kill-on-invalid-dep=yes) and there is nothing to report."
            if [[ -f "$log" ]]; then
                echo "Its log, $log, ends with:"
                tail -n 20 "$log" | sed 's/^/    /'
            else
                echo "Its log, $log, does not exist: the job could not start or write it."
            fi
            echo "Fix the cause and submit again: finished cells are kept."
        } >&2
        exit 1
    fi
    status=0
    "$mltbench" "$@" || status=$?
    # The cells still without results, with their tasks' logs (REPORT_ARGS: report NAME ...).
    if [[ -n "$array" ]]; then
        listing="$("$mltbench" run "${@:2}" --cells 2>/dev/null)" || listing=""
        while IFS=$'\t' read -r k label run state; do
            [[ -z "$k" || "$k" == \#* || "$state" == complete ]] && continue
            echo "mltbench job: cell $k ($label run $run) has no results; its log:" \
                "$prefix-cell-${array}_$k.out (submit again to run only the missing cells)" >&2
        done <<<"$listing"
    fi
    exit "$status"
    ;;
*)
    fail "unknown job kind $kind"
    ;;
esac
