#!/bin/bash
# submit.sh — submit one of the job arrays beside it and its merge, which
# waits until every task of the array has ended well (afterok):
#
#   contrib/slurm/submit.sh JOB [SBATCH_OPTION...] [-- EVFLOW_OPTION...]
#
#   JOB            merges into          shards in
#   model-grid     models/              parts/grid/K
#   textures       report/              parts/textures/K
#   narx           narx/                parts/narx/K
#   live           report-live/         parts/live/K
#
# Run it from the folder the jobs run in: the repository, or a scratch
# folder with graphs linked to the repository's. It creates logs/ and
# parts/ there first (slurmd opens a job's --output file before the script
# runs), refuses shards left from an earlier submission, and hands the jobs
# EVFLOW_BIN: as set, or the release build beside graphs/. SBATCH_OPTIONs
# (e.g. --array=1-4) override the script's #SBATCH lines; EVFLOW_OPTIONs
# are added to its evflow command. Example, the cut-down texture report:
#
#   contrib/slurm/submit.sh textures --array=1-4 --cpus-per-task=1 -- \
#       --samples plastic-sheet,felt-fabric --conditions 60:3,110:5 \
#       --profiles nominal,display-b --epochs 20 --iterations 20 --no-times
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

die() {
    echo "submit.sh: error: $*" >&2
    exit 1
}
usage() {
    awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}" >&2
    exit 2
}

job=${1:-}
[[ -n $job ]] || usage
shift
case $job in
model-grid) out=models parts=parts/grid ;;
textures) out=report parts=parts/textures ;;
narx) out=narx parts=parts/narx ;;
live) out=report-live parts=parts/live ;;
-h | --help) usage ;;
*) die "unknown job '$job': model-grid, textures, narx or live" ;;
esac

sbatch_opts=()
while (($#)) && [[ $1 != -- ]]; do
    sbatch_opts+=("$1")
    shift
done
if (($#)); then shift; fi # the --
evflow_args=("$@")

command -v sbatch >/dev/null || die "no sbatch on PATH: is Slurm installed? (contrib/slurm/setup-single-node.sh sets up one machine)"
[[ -d graphs ]] || die "no graphs/ in $PWD: run from the repository or a folder with graphs linked to it (ln -s /path/to/evflow/graphs graphs)"
EVFLOW_BIN=${EVFLOW_BIN:-$(readlink -f graphs)/../target/release/evflow}
[[ -x $EVFLOW_BIN ]] || die "no evflow at $EVFLOW_BIN: build it (cargo build --release -p evflow) or set EVFLOW_BIN=/path/to/evflow"
EVFLOW_BIN=$(readlink -f "$EVFLOW_BIN")
export EVFLOW_BIN

if [[ -d $parts ]] && [[ -n $(ls -A "$parts") ]]; then
    die "$parts/ holds shards of an earlier submission: merge them (sbatch $here/merge.sbatch $out $parts) or remove them (rm -r $parts) first"
fi
mkdir -p logs "$parts"

jid=$(sbatch --parsable "${sbatch_opts[@]}" "$here/$job.sbatch" "${evflow_args[@]}")
jid=${jid%%;*}
mid=$(sbatch --parsable --dependency="afterok:$jid" "$here/merge.sbatch" "$out" "$parts")
mid=${mid%%;*}
echo "array job $jid ($job.sbatch, evflow $EVFLOW_BIN): logs/ and $parts/"
echo "merge job $mid into $out/ once every task has ended well: logs/merge-$mid.out"
