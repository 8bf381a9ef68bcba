#!/usr/bin/env bash
# Submits a taxi-sim campaign to Slurm as N array tasks (one shard each) and the merge after them.
#
#   deploy/slurm/submit-campaign.sh CAMPAIGN.toml OUT N [campaign run flags...]
#
# Prints the two job ids ("<array> <merge>"). OUT must be on a filesystem every node sees;
# taxi-sim must be on PATH there (or TAXI_SIM=/path/to/taxi-sim, exported to the jobs).
set -euo pipefail
CAMPAIGN=${1:?usage: submit-campaign.sh CAMPAIGN.toml OUT N [flags]}
OUT=${2:?usage: submit-campaign.sh CAMPAIGN.toml OUT N [flags]}
N=${3:?usage: submit-campaign.sh CAMPAIGN.toml OUT N [flags]}
shift 3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$OUT"
array=$(sbatch --parsable --chdir "$OUT" --export=ALL --array="0-$((N - 1))" \
    "$here/campaign.sbatch" "$(realpath "$CAMPAIGN")" "$(realpath "$OUT")" "$@")
array=${array%%;*}
# afterany: the merge runs even if a shard failed, and says which variants are missing.
merge=$(sbatch --parsable --chdir "$OUT" --export=ALL --dependency="afterany:$array" \
    "$here/merge.sbatch" "$(realpath "$OUT")")
echo "$array ${merge%%;*}"
