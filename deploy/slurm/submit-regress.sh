#!/usr/bin/env bash
# Submits `taxi-sim regress` to Slurm as N array tasks (one shard each) and the merge after them,
# from the repository the paths are relative to.
#
#   deploy/slurm/submit-regress.sh OUT N PATHS... [regress flags]
#
# Prints the two job ids ("<array> <merge>"). The merge job writes OUT/regress.xml (JUnit),
# OUT/regress.jsonl and OUT/regress.md, the same as one machine's `taxi-sim regress PATHS
# --junit ... --json ... --summary ...`, wall times aside, and exits as that command would (0 all
# passed or known problems, 1 a case failed, 2 a file was bad). OUT must be on a filesystem
# every node sees; taxi-sim on PATH there (or TAXI_SIM=/path/to/taxi-sim, exported to the jobs).
set -euo pipefail
OUT=${1:?usage: submit-regress.sh OUT N PATHS... [flags]}
N=${2:?usage: submit-regress.sh OUT N PATHS... [flags]}
shift 2
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$OUT"
OUT=$(realpath "$OUT")
array=$(sbatch --parsable --chdir "$(pwd)" --output="$OUT/taxi-sim-regress-%A_%a.out" \
    --export=ALL --array="0-$((N - 1))" "$here/regress.sbatch" "$OUT" "$@")
array=${array%%;*}
# afterany: the merge runs even if a shard failed (its cases are then missing from the results).
merge=$(sbatch --parsable --chdir "$(pwd)" --output="$OUT/taxi-sim-regress-merge-%j.out" \
    --export=ALL --dependency="afterany:$array" --job-name=taxi-sim-regress-merge \
    --wrap="\"\${TAXI_SIM:-taxi-sim}\" regress --merge $OUT/regress-shard-*.jsonl --junit $OUT/regress.xml --json $OUT/regress.jsonl --summary $OUT/regress.md")
echo "$array ${merge%%;*}"
