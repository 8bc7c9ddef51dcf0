#!/usr/bin/env bash
# CI test of sharded runs on a real Slurm cluster of one node, started here for the test:
#
#   scripts/slurm/test-cluster.sh [TIMEOUT_SECONDS]     (default 600: the most the jobs may take)
#
# 1. Installs Slurm and munge if missing (Debian: slurmctld slurmd munge slurm-client).
# 2. In a temporary directory, starts a private munged (its own key and socket, so a system
#    munge, if any, is neither used nor disturbed), a slurmctld and a slurmd with a minimal
#    slurm.conf (SLURM_CONF points every Slurm command here at it), and waits for the node.
# 3. Writes a small spec, slurm-smoke.toml, runs it unsharded (`triorder run`) in one work
#    directory and as a 4-task job array plus merge job (scripts/slurm/submit.sh, with an sbatch
#    option, --time=10:00, that both jobs must show) in another, waits for the jobs, then
#    resubmits task 3 alone (`submit.sh --only 3`, after deleting its shard) to check the path a
#    user takes after a failed task.
# 4. Compares the merged results/slurm-smoke.csv with the unsharded one, column by column,
#    ignoring provenance: the columns machine, commit and seconds, and the value of rows whose
#    metric is `seconds` (timings).
# A trap stops exactly the daemons started here (by their pid files) and deletes the temporary
# directory on every exit path. Exits 0 if everything matched, 1 on any failure.
#
# The binary is $TRIORDER if set, else target/release/triorder (`cargo build --release`).
# Needs root (slurmd starts jobs as their user); re-runs itself under sudo otherwise.
# TRIORDER_SLURM_KEEP=1 keeps the temporary directory (logs, configuration) for a post-mortem.
set -euo pipefail

timeout_s=${1:-600}
[[ $timeout_s =~ ^[1-9][0-9]*$ ]] || { echo "usage: $0 [TIMEOUT_SECONDS]  (a positive whole number)" >&2; exit 2; }
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
started=$SECONDS

say() { printf '[slurm-test %3ds] %s\n' "$((SECONDS - started))" "$*"; }
fail() { echo "FAIL: $*" >&2; exit 1; }

# --- the binary ------------------------------------------------------------------------------
bin=${TRIORDER:-$repo/target/release/triorder}
[ -x "$bin" ] || fail "no triorder binary at $bin: build it with \`cargo build --release\`, or set TRIORDER"
bin="$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")"

# --- root ------------------------------------------------------------------------------------
# slurmd must run as root to start jobs (and SlurmUser=root keeps the setup to one user).
if [ "$(id -u)" != 0 ]; then
    command -v sudo >/dev/null || fail "needs root (or sudo) to run slurmd"
    say "re-running under sudo"
    keep=(TRIORDER="$bin" PATH="$PATH")
    for var in TRIORDER_DATA TRIORDER_SLURM_KEEP TMPDIR; do
        [ -z "${!var:-}" ] || keep+=("$var=${!var}")
    done
    exec sudo env "${keep[@]}" bash "${BASH_SOURCE[0]}" "$@"
fi

# --- packages --------------------------------------------------------------------------------
need=(sbatch squeue scontrol scancel sinfo slurmctld slurmd munged munge unmunge)
missing=()
for c in "${need[@]}"; do command -v "$c" >/dev/null || missing+=("$c"); done
if [ ${#missing[@]} -gt 0 ]; then
    say "installing slurmctld slurmd munge slurm-client (missing: ${missing[*]})"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurmctld slurmd munge slurm-client >/dev/null
fi
# csv lives in the full standard library (libpython3-stdlib, pulled in by python3), not in
# python3-minimal, so test the import rather than the command.
if ! python3 -c 'import csv' 2>/dev/null; then
    say "installing python3 (for the csv module)"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3 >/dev/null
fi
for c in "${need[@]}" python3; do command -v "$c" >/dev/null || fail "$c is still missing after installing"; done

# --- the temporary cluster -------------------------------------------------------------------
# Nothing from a surrounding Slurm (CI itself inside a job, a site's SBATCH_* defaults) may leak
# into the commands aimed at the private cluster.
while read -r var; do unset "$var"; done < <(compgen -e | grep -E '^(SLURM_|SBATCH_|SQUEUE_|SINFO_|SCONTROL_|SACCT_)' || true)

tmp=$(mktemp -d "${TMPDIR:-/tmp}/triorder-slurm.XXXXXX")
# slurm.conf takes paths unquoted.
[[ $tmp =~ ^[A-Za-z0-9_./-]+$ ]] || { rm -rf "$tmp"; fail "temporary directory $tmp has odd characters; set TMPDIR"; }

# The pid of a daemon we started, from its pid file, only if that process is still that daemon
# (a stale pid file must not make us kill something else).
daemon_pid() { # PIDFILE COMM
    local pid
    [ -s "$1" ] || return 1
    pid=$(tr -dc 0-9 <"$1")
    [ -n "$pid" ] && [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "$2" ] || return 1
    printf '%s\n' "$pid"
}
alive() { [ -e "/proc/$1" ] && ! grep -q '^[^)]*) Z' "/proc/$1/stat" 2>/dev/null; }

stop_daemon() { # PIDFILE COMM
    local pid i
    pid=$(daemon_pid "$1" "$2") || return 0
    kill -TERM "$pid" 2>/dev/null || return 0
    for ((i = 0; i < 150; i++)); do alive "$pid" || return 0; sleep 0.1; done
    echo "warning: $2 (pid $pid) did not stop on SIGTERM in 15 s: SIGKILL" >&2
    kill -KILL "$pid" 2>/dev/null || true
}

cleanup() {
    local rc=$?
    set +e
    trap - EXIT INT TERM HUP
    if [ -n "${tmp:-}" ] && [ -d "$tmp" ]; then
        # Jobs first, while slurmctld can still cancel them: a running job's slurmstepd would
        # outlive slurmd otherwise. This cluster is private, so every job in it is ours.
        if daemon_pid "$tmp/run/slurmctld.pid" slurmctld >/dev/null; then
            jobs=$(timeout 10 squeue -h -o %A 2>/dev/null | sort -u | tr '\n' ' ')
            if [ -n "${jobs// /}" ]; then
                # shellcheck disable=SC2086
                timeout 10 scancel $jobs 2>/dev/null
                for _ in $(seq 50); do [ -z "$(timeout 5 squeue -h 2>/dev/null)" ] && break; sleep 0.2; done
            fi
        fi
        if [ "$rc" != 0 ]; then
            for f in "$tmp"/log/slurmctld.log "$tmp"/log/slurmd.log "$tmp"/log/munged.log; do
                # (slurmd's complaints about the PMIx library it cannot load are noise.)
                [ -s "$f" ] && { echo "--- last lines of $f"; grep -v pmix "$f" | tail -n 15; }
            done
        fi
        stop_daemon "$tmp/run/slurmd.pid" slurmd
        stop_daemon "$tmp/run/slurmctld.pid" slurmctld
        stop_daemon "$tmp/run/munged.pid" munged
        if [ -n "${TRIORDER_SLURM_KEEP:-}" ]; then
            echo "kept $tmp (TRIORDER_SLURM_KEEP)"
        else
            rm -rf "$tmp"
        fi
    fi
    exit "$rc"
}
trap cleanup EXIT
# A signal becomes an ordinary exit, so the EXIT trap runs once, with a failing status.
trap 'exit 130' INT
trap 'exit 143' TERM
trap 'exit 129' HUP

# munged is strict about permissions: the key readable by its owner only, in a directory no one
# else can write, and the socket's directory (and mktemp's 0700 parent) searchable by all, or
# it refuses to start ("Socket is inaccessible: execute permissions for all required").
chmod 755 "$tmp"
mkdir -p "$tmp"/{munge,run,log,state,spool,work}
chmod 700 "$tmp/munge"
chmod 755 "$tmp/run"
key=$tmp/munge/munge.key
if command -v mungekey >/dev/null; then
    mungekey --create --keyfile="$key"
else
    dd if=/dev/urandom of="$key" bs=1 count=1024 status=none   # munge < 0.5.14 has no mungekey
fi
chmod 400 "$key"
socket=$tmp/run/munge.socket
munged --key-file="$key" --socket="$socket" --pid-file="$tmp/run/munged.pid" \
    --log-file="$tmp/log/munged.log" --seed-file="$tmp/munge/munged.seed" \
    || fail "munged did not start (see $tmp/log/munged.log)"
munge -S "$socket" -n | unmunge -S "$socket" >/dev/null || fail "munge cannot encode and decode with the private munged"
say "munged up ($socket)"

host=$(hostname -s 2>/dev/null || uname -n); host=${host%%.*}
cpus=$(nproc)
# Below the memory slurmd will measure, or it drains the node ("Low RealMemory").
mem_mib=$(awk '/^MemTotal:/ {m = int($2 / 1024); print (m > 1024 ? m - 512 : int(m / 2))}' /proc/meminfo)

# Ports: Slurm's defaults unless something (a system slurmctld, say) already listens there.
port_busy() { (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
free_port() { local p=$1; while port_busy "$p" || [ "$p" = "${2:-}" ]; do p=$((p + 1)); done; echo "$p"; }
ctld_port=$(free_port 6817)
slurmd_port=$(free_port 6818 "$ctld_port")

export SLURM_CONF=$tmp/slurm.conf
# Minimal for 22.05: one controller and one node, both on 127.0.0.1 so that no name has to
# resolve; root everywhere; no cgroups (proctrack/linuxproc, task/none), no accounting
# (sacct will not work: the test reads scontrol instead, hence MinJobAge, which keeps finished
# jobs in slurmctld's memory for an hour rather than 5 minutes); every path in $tmp.
cat >"$SLURM_CONF" <<EOF
ClusterName=triorder-ci
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MinJobAge=3600
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/run/slurmctld.pid
SlurmdPidFile=$tmp/run/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mib State=UNKNOWN
PartitionName=ci Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF

wait_for() { # SECONDS DESCRIPTION COMMAND...
    local limit=$1 what=$2 t0=$SECONDS
    shift 2
    until "$@" >/dev/null 2>&1; do
        ((SECONDS - t0 < limit)) || fail "$what: not within $limit s"
        sleep 0.5
    done
}
slurmctld || fail "slurmctld did not start"
wait_for 10 "slurmctld's pid file" daemon_pid "$tmp/run/slurmctld.pid" slurmctld
wait_for 30 "slurmctld answering (scontrol ping)" bash -c 'scontrol ping | grep -q UP'
slurmd -N "$host" || fail "slurmd did not start"
wait_for 10 "slurmd's pid file" daemon_pid "$tmp/run/slurmd.pid" slurmd
node_idle() { [ "$(sinfo -h -n "$host" -o %T)" = idle ]; }
wait_for 60 "node $host idle in sinfo" node_idle
say "cluster up: node $host, $cpus CPUs, ${mem_mib} MiB, ports $ctld_port/$slurmd_port ($tmp)"

# --- the spec and the unsharded reference ----------------------------------------------------
work=$tmp/work
spec=$work/slurm-smoke.toml
cat >"$spec" <<'EOF'
id = "slurm-smoke"
title = "Sharded run smoke test"
question = "Does a 4-task Slurm array reproduce the unsharded CSV?"
models = ["sphere:2000", "grid:32x32", "disk:950", "helix:3", "sphere:8000"]
methods = ["input", "random", "tipsify", "forsyth", "hilbert"]
caches = ["fifo:8..32/8"]
views = "ico:12"
res = 64
[figure]
kind = "line"
metric = "acmr"
x = "cache_size"
facet = "model"
EOF
mkdir -p "$work/unsharded" "$work/sharded"
say "unsharded run"
(cd "$work/unsharded" && "$bin" run "$spec") >"$tmp/log/unsharded.log" 2>&1 \
    || { cat "$tmp/log/unsharded.log"; fail "the unsharded \`triorder run\` failed"; }

# --- submission and waiting ------------------------------------------------------------------
shards=4
deadline=$((SECONDS + timeout_s))
export TRIORDER=$bin

submit() { # SUBMIT_ARGS...: sets array_id, merge_id
    local out
    out=$(cd "$work/sharded" && "$here/submit.sh" "$@" 2>&1) || { echo "$out"; fail "submit.sh $* failed"; }
    array_id=$(awk '$1 == "array" && $2 == "job:" {print $3}' <<<"$out")
    merge_id=$(awk '$1 == "merge" && $2 == "job:" {print $3}' <<<"$out")
    { [ -n "$array_id" ] && [ -n "$merge_id" ]; } || { echo "$out"; fail "no job ids in submit.sh's output"; }
    say "submit.sh $*: array job $array_id, merge job $merge_id"
}

field() { grep -o "\(^\| \)$1=[^ ]*" <<<"$2" | head -n 1 | cut -d= -f2-; }
records() { scontrol -o show job "$1" 2>/dev/null; }   # one line per array task (or pending block)
terminal() {
    case $1 in
        COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|PREEMPTED|BOOT_FAIL|DEADLINE) return 0 ;;
        *) return 1 ;;
    esac
}

# Waits until every task of the array has ended and the merge job has either ended or can no
# longer start (its afterok dependency failed: it would stay PENDING forever).
wait_jobs() { # ARRAY MERGE
    local line state all_done recs m
    while :; do
        ((SECONDS < deadline)) || { squeue; fail "jobs $1/$2 not finished within $timeout_s s"; }
        recs=$(records "$1") || fail "slurmctld does not know the array job $1"
        all_done=1
        while read -r line; do
            terminal "$(field JobState "$line")" || all_done=0
        done <<<"$recs"
        if [ "$all_done" = 1 ]; then
            m=$(records "$2") || fail "slurmctld does not know the merge job $2"
            state=$(field JobState "$m")
            terminal "$state" && return 0
            [ "$state" = PENDING ] && [ "$(field Reason "$m")" = DependencyNeverSatisfied ] && return 0
        fi
        sleep 1
    done
}

report_and_check() { # ARRAY MERGE: prints each job's state; fails on any failed job
    local recs m line k state failed=0 log
    recs=$(records "$1")
    while read -r line; do
        k=$(field ArrayTaskId "$line")
        state=$(field JobState "$line")
        say "  task $k (job $(field JobId "$line")): $state, elapsed $(field RunTime "$line"), exit $(field ExitCode "$line")"
        [ "$(field TimeLimit "$line")" = 00:10:00 ] || fail "task $k: time limit $(field TimeLimit "$line"), not submit.sh's --time=10:00"
        if [ "$state" != COMPLETED ]; then
            failed=1
            log=$work/sharded/results/slurm/slurm-smoke-$1_$k.out
            echo "--- $log"; cat "$log" 2>/dev/null || echo "(no log)"
        fi
    done < <(while read -r line; do echo "$(field ArrayTaskId "$line") $line"; done <<<"$recs" | sort -n | cut -d' ' -f2-)
    m=$(records "$2")
    state=$(field JobState "$m")
    log=$work/sharded/results/slurm/slurm-smoke-merge-$2.out
    say "  merge (job $2): $state ($(field Reason "$m")), elapsed $(field RunTime "$m"), exit $(field ExitCode "$m")"
    [ "$(field TimeLimit "$m")" = 00:10:00 ] || fail "merge: time limit $(field TimeLimit "$m"), not submit.sh's --time=10:00"
    if [ "$failed" = 1 ]; then
        # afterok must have held the merge back: it may not have run, not even partly.
        if [ "$state" = PENDING ] && [ ! -e "$log" ]; then
            say "  the merge job did not run (its afterok dependency failed): cancelling it"
            scancel "$2"
        else
            echo "--- $log"; cat "$log" 2>/dev/null
            fail "a task failed, yet the merge job $2 is $state"
        fi
        fail "array job $1: a task failed (its log is above)"
    fi
    if [ "$state" != COMPLETED ]; then
        echo "--- $log"; cat "$log" 2>/dev/null || echo "(no log)"
        fail "merge job $2: $state"
    fi
}

compare() { # what: compares the merged CSV with the unsharded one
    python3 - "$work/unsharded/results/slurm-smoke.csv" "$work/sharded/results/slurm-smoke.csv" <<'PY'
import csv, sys
IGNORED = {"machine", "commit", "seconds"}  # provenance: where, from what source, how long
ref_path, got_path = sys.argv[1:3]
def load(path):
    with open(path, newline="") as f:
        return list(csv.reader(f))
ref, got = load(ref_path), load(got_path)
problems = []
if not ref or not got:
    problems.append("an empty file")
elif ref[0] != got[0]:
    problems.append(f"headers differ:\n  unsharded {ref[0]}\n  merged    {got[0]}")
else:
    head = ref[0]
    metric = head.index("metric") if "metric" in head else None
    value = head.index("value") if "value" in head else None
    if len(ref) != len(got):
        problems.append(f"{len(ref) - 1} rows unsharded, {len(got) - 1} merged")
    for line, (a, b) in enumerate(zip(ref[1:], got[1:]), start=2):
        if len(a) != len(head) or len(b) != len(head):
            problems.append(f"line {line}: {len(a)} and {len(b)} fields for {len(head)} columns")
            continue
        timing = metric is not None and a[metric] == "seconds" and b[metric] == "seconds"
        for i, name in enumerate(head):
            if name in IGNORED or (timing and i == value):
                continue
            if a[i] != b[i]:
                problems.append(f"line {line}, column {name}: unsharded {a[i]!r}, merged {b[i]!r}")
    if problems and len(ref) == len(got):
        # Say whether it is only the order that differs: a merge that sorts wrongly.
        strip = lambda rows: sorted(tuple(v for i, v in enumerate(r) if head[i] not in IGNORED and not (metric is not None and r[metric] == "seconds" and i == value)) for r in rows[1:])
        if strip(ref) == strip(got):
            problems.insert(0, "the same rows, in a different order")
rows = max(len(ref) - 1, 0)
print(f"rows compared: {rows}, columns ignored: {', '.join(sorted(IGNORED))} and the value of `seconds` rows")
if problems:
    print(f"identical: no ({len(problems)} differences)")
    for p in problems[:20]:
        print("  " + p)
    sys.exit(1)
print("identical: yes")
PY
}

cd "$work/sharded"
say "submitting $shards shards"
submit "$spec" "$shards" --time=10:00
first_array=$array_id first_merge=$merge_id
wait_jobs "$array_id" "$merge_id"
report_and_check "$array_id" "$merge_id"
say "comparison, merged vs unsharded:"
compare || fail "the merged CSV differs from the unsharded one"

# The way back from a failed task: its shard gone, that task alone and a new merge.
merged=$work/sharded/results/slurm-smoke.csv
rm -f "$work/sharded/results/slurm-smoke.shard-3-of-$shards.csv" "$merged"
say "resubmitting task 3 alone (its shard deleted)"
submit --only 3 "$spec" "$shards" --time=10:00
wait_jobs "$array_id" "$merge_id"
report_and_check "$array_id" "$merge_id"
[ -s "$work/sharded/results/slurm-smoke.shard-3-of-$shards.csv" ] || fail "task 3 did not write its shard again"
say "comparison after the resubmission:"
compare || fail "the merged CSV differs from the unsharded one after resubmitting task 3"

say "PASS: array job $first_array (merge $first_merge), resubmission $array_id (merge $merge_id); $((SECONDS - started)) s in all"
