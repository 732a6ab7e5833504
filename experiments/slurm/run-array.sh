#!/usr/bin/env bash
# Spreads an mltbench experiment over a Slurm cluster: one array task per independent
# (estimator, run) cell, then one job that merges them into the report.
#
#   experiments/slurm/run-array.sh caustic          # from the repository root
#
# It submits three jobs: `prepare` renders (or finds) the cached reference once; the array
# runs `mltbench run NAME --cell K` for every cell, after it; `report` merges whatever cells
# finished, after the array. Results land in results/NAME/ on the shared filesystem, as
# a single-machine `mltbench run NAME` would write them. Edit the #SBATCH-style options
# below (partition, time, CPUs) to suit the cluster.
#
# Extra options: --quick and --results DIR go to every job; --fresh only to `prepare`, which
# clears results/NAME/ once before the array starts; anything else to the `run` jobs.
# MLTBENCH=/path/to/mltbench uses that binary instead of building one.
set -euo pipefail

name="${1:?usage: run-array.sh EXPERIMENT [extra mltbench run options]}"
shift
run_opts=()
report_opts=()
fresh=()
while (($#)); do
    case "$1" in
        --fresh) fresh=(--fresh) ;;
        --quick | --results=*) run_opts+=("$1"); report_opts+=("$1") ;;
        --results) run_opts+=("$1" "${2:?--results needs a folder}"); report_opts+=("$1" "$2"); shift ;;
        *) run_opts+=("$1") ;;
    esac
    shift
done
cpus="${CPUS_PER_CELL:-2}"
limit="${CELL_TIME_LIMIT:-01:00:00}"
partition_opt=()
if [[ -n "${PARTITION:-}" ]]; then partition_opt=(--partition "$PARTITION"); fi

if [[ -n "${MLTBENCH:-}" ]]; then
    bin="$MLTBENCH"
else
    cargo build --release
    bin="$PWD/target/release/mltbench"
fi
cells=$("$bin" run "$name" --cells "${run_opts[@]}" | grep -vc '^#')
mkdir -p results/slurm-logs

prepare=$(sbatch --parsable "${partition_opt[@]}" --job-name "$name-prepare" \
    --cpus-per-task "$cpus" --time "$limit" --output "results/slurm-logs/$name-prepare-%j.out" \
    --wrap "$bin run $name --prepare --threads $cpus ${fresh[*]} ${run_opts[*]}")

array=$(sbatch --parsable "${partition_opt[@]}" --job-name "$name-cells" \
    --dependency "afterok:$prepare" --array "0-$((cells - 1))" \
    --cpus-per-task "$cpus" --time "$limit" --output "results/slurm-logs/$name-cell-%a-%j.out" \
    --wrap "$bin run $name --cell \$SLURM_ARRAY_TASK_ID --threads $cpus ${run_opts[*]}")

report=$(sbatch --parsable "${partition_opt[@]}" --job-name "$name-report" \
    --dependency "afterany:$array" --cpus-per-task 1 --time 00:30:00 \
    --output "results/slurm-logs/$name-report-%j.out" \
    --wrap "$bin report $name ${report_opts[*]}")

echo "submitted: prepare $prepare, $cells cells as array $array, report $report"
