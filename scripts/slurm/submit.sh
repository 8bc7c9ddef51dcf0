#!/usr/bin/env bash
# Runs one experiment spec as a Slurm job array: N shard tasks, then a merge job.
#
#   scripts/slurm/submit.sh [--only LIST] SPEC N [SBATCH_OPTION...]
#
#   SPEC            an experiment spec, e.g. experiments/ID.toml (ID = the file's stem)
#   N               how many shards (array tasks) to cut the spec's work into
#   --only LIST     resubmit only these tasks, e.g. --only 3,5 or --only 2-4,7 (each in 1..N),
#                   plus a new merge job; for tasks that failed (see the end of the output)
#   SBATCH_OPTION   anything else goes to both sbatch calls, e.g. --partition=x --time=1:00:00
#                   (not --array, --dependency, --wrap or --chdir: this script sets those)
#
# Task K runs `triorder run SPEC --shard K/N` (writes results/ID.shard-K-of-N.csv); the merge
# job, which starts only once every task has succeeded (--dependency=afterok), runs
# `triorder merge SPEC` (checks all N shard files and writes results/ID.csv, the file an
# unsharded `triorder run SPEC` writes). A shard already complete is skipped by triorder
# itself, so resubmitting tasks (or the whole array) never redoes finished work.
#
# Everything runs in the current directory (results/ are written relative to it), which, like
# the triorder binary and the spec, must be visible from the compute nodes (a shared file system).
# The binary is $TRIORDER if set, else target/release/triorder of this repository
# (`cargo build --release`). TRIORDER_DATA, if set, is handed to every job. Logs go to
# results/slurm/: ID-ARRAYJOB_K.out for task K and ID-merge-JOB.out for the merge.
#
# Prints the job ids on lines `  array job: ID` and `  merge job: ID` (scripts/slurm/test-cluster.sh
# reads them), and how to follow the jobs. Exits 2 on a usage error, 1 if sbatch fails.
set -euo pipefail

die() { echo "error: $*" >&2; exit 2; }
usage() { sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "$0"; }

# Quotes a word for /bin/sh: the --wrap command is run by sh (sbatch writes `#!/bin/sh` above
# it), so bash's printf %q, which may produce $'...', is not safe here. Single quotes are.
shq() { printf "'%s'" "$(printf '%s' "$1" | sed "s/'/'\\\\''/g")"; }

# --- arguments ------------------------------------------------------------------------------
only=""
positional=()
sbatch_extra=()
while [ $# -gt 0 ]; do
    case $1 in
        -h|--help) usage; exit 0 ;;
        --only) [ $# -ge 2 ] || die "--only needs a list of task ids, e.g. --only 3,5"; only=$2; shift 2 ;;
        --only=*) only=${1#--only=}; shift ;;
        # Options that would break the array/merge contract this script sets up.
        --array|--array=*|-a|-a?*) die "do not pass $1: use N (all tasks) or --only LIST (some)" ;;
        --dependency|--dependency=*|-d|-d?*) die "do not pass $1: the merge job's dependency is set here" ;;
        --wrap|--wrap=*) die "do not pass $1: the job commands are set here" ;;
        --chdir|--chdir=*|-D|-D?*) die "do not pass $1: jobs run in the current directory; cd there first" ;;
        -*) if [ ${#positional[@]} -lt 2 ]; then
                die "unknown option $1 before SPEC N (sbatch options go after them; see --help)"
            fi
            sbatch_extra+=("$1"); shift ;;
        *) if [ ${#positional[@]} -lt 2 ]; then positional+=("$1"); else sbatch_extra+=("$1"); fi; shift ;;
    esac
done
[ ${#positional[@]} -eq 2 ] || die "expected SPEC and N: $0 [--only LIST] SPEC N [SBATCH_OPTION...] (--help explains)"
spec_arg=${positional[0]}
shards=${positional[1]}

[[ $shards =~ ^[1-9][0-9]*$ ]] || die "N must be a positive whole number (the number of shards), not '$shards'"
[ -e "$spec_arg" ] || die "no such spec: $spec_arg"
{ [ -f "$spec_arg" ] && [ -r "$spec_arg" ]; } || die "not a readable file: $spec_arg"
# Absolute, so the jobs find it whatever their working directory.
spec="$(cd "$(dirname "$spec_arg")" && pwd)/$(basename "$spec_arg")"
id=$(basename "$spec_arg"); id=${id%.*}

# The tasks to submit: all, or a validated subset (sbatch's --array syntax: K and K-L items).
if [ -n "$only" ]; then
    [[ $only =~ ^[0-9]+(-[0-9]+)?(,[0-9]+(-[0-9]+)?)*$ ]] \
        || die "--only '$only': expected task ids and ranges such as 3,5 or 2-4,7"
    IFS=, read -r -a items <<<"$only"
    for item in "${items[@]}"; do
        lo=${item%-*}; hi=${item#*-}
        # 10# so that ids like 08 are not read as octal.
        if ((10#$lo < 1 || 10#$hi > shards || 10#$lo > 10#$hi)); then
            die "--only '$only': '$item' is not within 1..$shards"
        fi
    done
    array=$only
else
    array="1-$shards"
fi

# --- the binary, the data directory, sbatch --------------------------------------------------
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
if [ -n "${TRIORDER:-}" ]; then
    bin=$TRIORDER
    [ -e "$bin" ] || die "TRIORDER=$bin: no such file"
else
    bin="$repo/target/release/triorder"
    [ -e "$bin" ] || die "no triorder binary at $bin: build it with \`cargo build --release\` (in $repo), or set TRIORDER=/path/to/triorder"
fi
{ [ -f "$bin" ] && [ -x "$bin" ]; } || die "$bin is not an executable file"
bin="$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")"
# Fail here, once, rather than in N tasks, if the binary predates sharded runs.
if ! "$bin" run --help 2>&1 | grep -q -- '--shard'; then
    die "$bin does not know \`run --shard\` (an older build?): rebuild with \`cargo build --release\`"
fi

data_setup=""
if [ -n "${TRIORDER_DATA:-}" ]; then
    data=$TRIORDER_DATA
    if [ -d "$data" ]; then
        data="$(cd "$data" && pwd)"
    else
        echo "warning: TRIORDER_DATA=$data is not a directory here; passing it to the jobs as it is" >&2
    fi
    # Written into the job command, not only left in the environment: sbatch exports the
    # environment by default, but not under --export=NONE or a site's SBATCH_EXPORT.
    data_setup="TRIORDER_DATA=$(shq "$data"); export TRIORDER_DATA; "
fi

command -v sbatch >/dev/null || die "sbatch not found: run this on a Slurm submit host (or install slurm-client)"

# Slurm does not create the directory of --output: without it the jobs fail with no log at all.
mkdir -p results/slurm
logdir="$PWD/results/slurm"
# In --output, % starts a pattern (%A, %a, %x, %j) wherever it is, so a literal one is %%.
logpat=${logdir//%/%%}

# sbatch --parsable prints JOBID or JOBID;CLUSTER.
submit() {
    local out
    out=$(sbatch --parsable "$@") || return 1
    out=${out%%;*}
    [[ $out =~ ^[0-9]+$ ]] || { echo "error: sbatch printed '$out', not a job id" >&2; return 1; }
    printf '%s\n' "$out"
}

# Our defaults first, the caller's options next (so a --job-name, --output or --export of
# theirs wins), the array and dependency last (the caller may not set those; checked above).
common=(--chdir="$PWD")

task_cmd="${data_setup}echo \"triorder shard \$SLURM_ARRAY_TASK_ID/$shards of $(shq "$id") on \$(hostname)\"; exec $(shq "$bin") run $(shq "$spec") --shard \"\$SLURM_ARRAY_TASK_ID/$shards\""
array_id=$(submit "${common[@]}" --job-name="$id" --output="$logpat/%x-%A_%a.out" \
    ${sbatch_extra[@]+"${sbatch_extra[@]}"} --array="$array" --wrap="$task_cmd") \
    || { echo "error: sbatch refused the array job (its message is above)" >&2; exit 1; }

merge_cmd="${data_setup}echo \"triorder merge of $(shq "$id") on \$(hostname)\"; exec $(shq "$bin") merge $(shq "$spec")"
if ! merge_id=$(submit "${common[@]}" --job-name="$id-merge" --output="$logpat/%x-%j.out" \
    ${sbatch_extra[@]+"${sbatch_extra[@]}"} --dependency="afterok:$array_id" --wrap="$merge_cmd"); then
    echo "error: sbatch refused the merge job (its message is above); the array job $array_id is queued:" >&2
    echo "       merge by hand once it is done (cd $PWD && $bin merge $spec), or scancel $array_id" >&2
    exit 1
fi

# --- how to follow ---------------------------------------------------------------------------
again=$(printf ' %q' "${sbatch_extra[@]+"${sbatch_extra[@]}"}")
[ ${#sbatch_extra[@]} -gt 0 ] || again=""
self=$(printf '%q' "$0")
cat <<EOF
Submitted $id ($spec) in $shards shards from $PWD:
  array job: $array_id
  merge job: $merge_id
Tasks $array (of 1-$shards) run \`triorder run SPEC --shard K/$shards\`; the merge runs after they all succeed.

Follow:
  squeue -j $array_id,$merge_id
  scontrol show job $array_id          (each task's state, while Slurm remembers it)
  sacct -j $array_id,$merge_id -X --format=JobID,JobName,State,Elapsed,ExitCode   (needs accounting)
Logs:
  $logdir/$id-${array_id}_K.out   (task K)
  $logdir/$id-merge-$merge_id.out
If a task fails, the merge job $merge_id never starts (squeue shows DependencyNeverSatisfied):
  scancel $merge_id
  $self --only K $(printf '%q' "$spec_arg") $shards$again   (task K alone, and a new merge)
Merged CSV: $PWD/results/$id.csv
EOF

# A merge job of an earlier submission whose array had failed waits forever: point it out.
if [ -n "$only" ] && command -v squeue >/dev/null; then
    stale=$(squeue -h -u "$(id -un)" -n "$id-merge" -t PENDING -o '%i %r' 2>/dev/null \
        | awk -v new="$merge_id" '$1 != new && /DependencyNeverSatisfied/ {print $1}' | paste -sd, -)
    if [ -n "$stale" ]; then
        echo "note: earlier merge job(s) $stale can never start (their array failed): scancel ${stale//,/ }"
    fi
fi
