#!/usr/bin/env bash
# Spreads an mltbench experiment over a Slurm cluster: one array task per (estimator, run)
# cell that is not complete yet, then one job that merges the cells into the report.
#
#   experiments/slurm/run-array.sh NAME [options]
#
# NAME is an experiment name or the path of its .toml file, as `mltbench run` takes it. Three
# jobs are submitted: `prepare` renders (or finds) the cached reference once; the array runs
# `mltbench run NAME --cell K` for every cell not complete yet, after it; `report` merges the
# cells present, after the array. Results land in RESULTS/NAME/ (RESULTS/NAME-quick/ with
# --quick), RESULTS being `results` or the --results folder, on the filesystem the nodes
# share, as a single-machine `mltbench run NAME` would write them; the jobs' logs go to
# RESULTS/slurm-logs/. Submitting again queues only the cells still missing.
#
# Options:
#   --quick, --results DIR   to every job
#   --fresh                  to `prepare` only: it clears the results once, before the array
#   --threads N              threads of each job (default: its CPUs, CPUS_PER_CELL)
#   --sbatch-arg ARG         given to every sbatch after the script's own options, so it can
#                            override them (repeatable): --sbatch-arg=--account=proj42
#   anything else            to the cell jobs (checked by `mltbench run NAME --cells` first)
#
# Environment:
#   CPUS_PER_CELL            CPUs of the prepare job and of each cell (default 2, or --threads)
#   PARTITION                partition of every job
#   CELL_TIME_LIMIT          time limit of each cell (default 01:00:00)
#   PREPARE_TIME_LIMIT       time limit of the prepare job (default: CELL_TIME_LIMIT)
#   REPORT_TIME_LIMIT        time limit of the report job (default 00:30:00)
#   CPU_LEVELS               the x86-64 levels to build (default "x86-64-v2 x86-64-v3
#                            x86-64-v4"); each job runs the highest its node supports
#   MLTBENCH                 a binary to use on every node instead of building, or a folder
#                            of builds laid out as this script makes them (LEVEL/release/)
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
job="$here/job.sh"
die() {
    echo "run-array.sh: $*" >&2
    exit 2
}

name="${1:-}"
[[ -n "$name" && "$name" != -* ]] ||
    die "usage: run-array.sh EXPERIMENT [--quick] [--results DIR] [--fresh] [--threads N] [--sbatch-arg ARG]..."
shift
quick=()
results=results
fresh=()
threads=""
cell_opts=()
sbatch_args=()
while (($#)); do
    case "$1" in
    --quick) quick=(--quick) ;;
    --fresh) fresh=(--fresh) ;;
    --results=*) results="${1#--results=}" ;;
    --results) (($# >= 2)) || die "--results needs a folder"; results="$2"; shift ;;
    --threads=*) threads="${1#--threads=}" ;;
    --threads) (($# >= 2)) || die "--threads needs a number"; threads="$2"; shift ;;
    --sbatch-arg=*) sbatch_args+=("${1#--sbatch-arg=}") ;;
    --sbatch-arg) (($# >= 2)) || die "--sbatch-arg needs an argument"; sbatch_args+=("$2"); shift ;;
    --cell | --cell=* | --cells | --prepare) die "$1: the script chooses the cells itself" ;;
    *) cell_opts+=("$1") ;;
    esac
    shift
done
[[ -n "$results" ]] || die "--results needs a folder"
if [[ -n "$threads" && ! "$threads" =~ ^[1-9][0-9]*$ ]]; then
    die "--threads $threads: give a number of threads >= 1"
fi
cpus="${CPUS_PER_CELL:-${threads:-2}}"
[[ "$cpus" =~ ^[1-9][0-9]*$ ]] || die "CPUS_PER_CELL=$cpus: give a number of CPUs >= 1"
threads="${threads:-$cpus}"
cell_limit="${CELL_TIME_LIMIT:-01:00:00}"
prepare_limit="${PREPARE_TIME_LIMIT:-$cell_limit}"
report_limit="${REPORT_TIME_LIMIT:-00:30:00}"
common=(--chdir "$PWD")
if [[ -n "${PARTITION:-}" ]]; then common+=(--partition "$PARTITION"); fi

# The binaries: one per x86-64 level, so that every node runs a build it supports (the
# default `-C target-cpu=native` of .cargo/config.toml would fit the login node only).
if [[ -n "${MLTBENCH:-}" ]]; then
    bin="$MLTBENCH"
else
    read -r -a levels <<<"${CPU_LEVELS:-x86-64-v2 x86-64-v3 x86-64-v4}"
    ((${#levels[@]})) || die "CPU_LEVELS is empty"
    for level in "${levels[@]}"; do
        case "$level" in
        x86-64 | x86-64-v2 | x86-64-v3 | x86-64-v4) ;;
        *) die "CPU_LEVELS: $level is not one of x86-64, x86-64-v2, x86-64-v3, x86-64-v4" ;;
        esac
    done
    bin="${CARGO_TARGET_DIR:-$repo/target}/slurm"
    for level in "${levels[@]}"; do
        echo "run-array.sh: building mltbench for $level" >&2
        env -u CARGO_ENCODED_RUSTFLAGS RUSTFLAGS="-C target-cpu=$level" \
            cargo build --release --locked --bin mltbench \
            --manifest-path "$repo/Cargo.toml" --target-dir "$bin/$level"
    done
fi
here_bin="$("$job" pick "$bin")"

# Which cells are not complete yet (all of them with --fresh); this also checks NAME and the
# options before anything is submitted.
run_args=(run "$name" "${quick[@]}" --results "$results")
listing="$("$here_bin" "${run_args[@]}" --cells "${cell_opts[@]}")"
header="$(head -n 1 <<<"$listing")"
base="${header#\# }"
base="${base%%: *}"
todo=()
total=0
while IFS= read -r line; do
    [[ -z "$line" || "$line" == \#* ]] && continue
    total=$((total + 1))
    if ((${#fresh[@]})) || [[ "${line##*$'\t'}" != complete ]]; then
        todo+=("${line%%$'\t'*}")
    fi
done <<<"$listing"
((total)) || die "$name has no cells"

# The array's index list, runs of consecutive cells as ranges: 0-3,5,7-9.
ranges=""
i=0
while ((i < ${#todo[@]})); do
    j=$i
    while ((j + 1 < ${#todo[@]} && todo[j + 1] == todo[j] + 1)); do j=$((j + 1)); done
    ranges+="${ranges:+,}${todo[i]}"
    ((j > i)) && ranges+="-${todo[j]}"
    i=$((j + 1))
done

mkdir -p "$results/slurm-logs"
logs="$(cd "$results/slurm-logs" && pwd)"
pattern="${logs//%/%%}/$base" # Slurm expands % in --output: keep the folder's own literal
submitted=()
# submit VAR SBATCH_ARGS...: submits a job and sets VAR to its id.
submit() {
    local var="$1" id
    shift
    if ! id="$(sbatch --parsable "$@")"; then
        # Leaves nothing half-submitted behind.
        if ((${#submitted[@]})); then scancel "${submitted[@]}" 2>/dev/null || true; fi
        die "sbatch failed${submitted[*]:+; cancelled the jobs already submitted (${submitted[*]})}"
    fi
    id="${id%%;*}" # "id;cluster" on multi-cluster sites
    submitted+=("$id")
    printf -v "$var" '%s' "$id"
}

prepare=""
array=""
if ((${#todo[@]})); then
    submit prepare "${common[@]}" --job-name "$base-prepare" --cpus-per-task "$cpus" \
        --time "$prepare_limit" --output "$pattern-prepare-%j.out" "${sbatch_args[@]}" \
        "$job" prepare "$bin" "$logs/$base" -- \
        "${run_args[@]}" --prepare "${fresh[@]}" --threads "$threads"
    # --kill-on-invalid-dep: if `prepare` fails, Slurm cancels the array instead of keeping
    # it pending forever; `report` then runs and says why.
    submit array "${common[@]}" --job-name "$base-cells" --array "$ranges" \
        --dependency "afterok:$prepare" --kill-on-invalid-dep=yes --cpus-per-task "$cpus" \
        --time "$cell_limit" --output "$pattern-cell-%A_%a.out" "${sbatch_args[@]}" \
        "$job" cell "$bin" -- "${run_args[@]}" --threads "$threads" "${cell_opts[@]}"
fi
report_opts=(--cpus-per-task 1 --time "$report_limit" --output "$pattern-report-%j.out")
if [[ -n "$array" ]]; then
    report_opts+=(--dependency "afterany:$array" --kill-on-invalid-dep=yes)
fi
submit report "${common[@]}" --job-name "$base-report" "${report_opts[@]}" \
    "${sbatch_args[@]}" "$job" report "$bin" "$logs/$base" "$prepare" "$array" -- \
    report "$name" "${quick[@]}" --results "$results"

if [[ -n "$array" ]]; then
    echo "submitted: prepare $prepare, ${#todo[@]} of $total cells as array $array ($ranges)," \
        "report $report"
    echo "logs: $logs/$base-prepare-$prepare.out, $base-cell-${array}_K.out," \
        "$base-report-$report.out"
    echo "if the prepare job fails, Slurm cancels the array and the report job's log says why"
else
    echo "all $total cells are complete: submitted only the report, job $report"
    echo "log: $logs/$base-report-$report.out"
fi
echo "results: $results/$base/"
