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
set -euo pipefail

name="${1:?usage: run-array.sh EXPERIMENT [extra mltbench run options]}"
shift
extra=("$@")
cpus="${CPUS_PER_CELL:-2}"
limit="${CELL_TIME_LIMIT:-01:00:00}"
partition_opt=()
if [[ -n "${PARTITION:-}" ]]; then partition_opt=(--partition "$PARTITION"); fi

cargo build --release
bin="$PWD/target/release/mltbench"
cells=$("$bin" run "$name" --cells "${extra[@]}" | grep -vc '^#')
mkdir -p results/slurm-logs

prepare=$(sbatch --parsable "${partition_opt[@]}" --job-name "$name-prepare" \
    --cpus-per-task "$cpus" --time "$limit" --output "results/slurm-logs/$name-prepare-%j.out" \
    --wrap "$bin run $name --prepare --threads $cpus ${extra[*]}")

array=$(sbatch --parsable "${partition_opt[@]}" --job-name "$name-cells" \
    --dependency "afterok:$prepare" --array "0-$((cells - 1))" \
    --cpus-per-task "$cpus" --time "$limit" --output "results/slurm-logs/$name-cell-%a-%j.out" \
    --wrap "$bin run $name --cell \$SLURM_ARRAY_TASK_ID --threads $cpus ${extra[*]}")

report=$(sbatch --parsable "${partition_opt[@]}" --job-name "$name-report" \
    --dependency "afterany:$array" --cpus-per-task 1 --time 00:30:00 \
    --output "results/slurm-logs/$name-report-%j.out" \
    --wrap "$bin report $name ${extra[*]}")

echo "submitted: prepare $prepare, $cells cells as array $array, report $report"
