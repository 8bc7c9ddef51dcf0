#!/usr/bin/env bash
# Fuzzes every parser of untrusted input (issue 20) with libFuzzer through cargo-fuzz.
#
#   scripts/fuzz.sh SECONDS [TARGET...]   build the targets of fuzz/ and run each for SECONDS
#                                         (default: every target: obj ply gltf glb spec)
#
# Each target's corpus (fuzz/corpus/TARGET, kept between runs, not committed) is seeded from
# fuzz/seeds/TARGET (small valid files, made by fuzz/seeds/generate.py), the broken inputs of
# tests/data/bad/ and the bundled assets/ and experiments/ of the same format. libFuzzer reports
# as a crash any panic, any input that runs longer than $FUZZ_TIMEOUT s (default 10), any single
# allocation over $FUZZ_MALLOC_LIMIT_MB (default 64) and a peak resident size over
# $FUZZ_RSS_LIMIT_MB (default 1024): no input of the corpus' sizes may make a loader allocate
# that much, whatever counts its header declares. Crashing inputs are left in
# fuzz/artifacts/TARGET/ (`cargo +nightly fuzz fmt TARGET FILE` shows one); reproduce one with
# `cargo +nightly fuzz run TARGET FILE`.
#
# Prints, per target: executions, coverage (libFuzzer's cov: edges and ft: features), corpus
# size, and what it found; libFuzzer's whole output is left in fuzz/logs/TARGET.log. Exits 1 if
# any target found anything, 2 if the build failed.
#
# Needs the nightly toolchain (`rustup toolchain install nightly`) and cargo-fuzz
# (`cargo install cargo-fuzz --locked`). The targets are built optimized, with debug assertions
# and overflow checks, and with AddressSanitizer (cargo-fuzz's defaults): its allocator is what
# lets libFuzzer's -malloc_limit_mb see every allocation, even one never touched. FUZZ_SANITIZER=none
# builds without it (faster runs, but then only the resident-size limit catches memory).
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${1:?usage: scripts/fuzz.sh SECONDS [TARGET...]}
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(obj ply gltf glb spec)
sanitizer=${FUZZ_SANITIZER:-address}
timeout=${FUZZ_TIMEOUT:-10}
malloc_limit=${FUZZ_MALLOC_LIMIT_MB:-64}
rss_limit=${FUZZ_RSS_LIMIT_MB:-1024}
root=$PWD

# Those of the paths given that exist, one a line.
existing() { for f in "$@"; do if [ -e "$f" ]; then echo "$f"; fi; done; }

# The seed files of TARGET, one path a line.
seeds() {
    case $1 in
        # assets/spot.obj (330 KB) would slow every execution a hundredfold; fuzz/seeds/obj has
        # an excerpt of it.
        obj) existing fuzz/seeds/obj/* tests/data/bad/*.obj ;;
        ply) existing fuzz/seeds/ply/* tests/data/bad/*.ply ;;
        gltf) existing fuzz/seeds/gltf/* tests/data/bad/*.gltf ;;
        glb) existing fuzz/seeds/glb/* tests/data/bad/*.glb assets/*.glb ;;
        spec) existing experiments/*.toml ;;
        *) echo "scripts/fuzz.sh: unknown target '$1' (obj ply gltf glb spec)" >&2; exit 2 ;;
    esac
}

for t in "${targets[@]}"; do seeds "$t" >/dev/null; done

fuzz() { cargo +nightly fuzz "$1" --fuzz-dir fuzz "${@:2}"; }

echo "== building the fuzz targets (cargo +nightly fuzz build, sanitizer $sanitizer)"
if ! fuzz build --sanitizer "$sanitizer"; then
    echo "scripts/fuzz.sh: building the fuzz targets failed" >&2
    exit 2
fi

logs=$root/fuzz/logs
mkdir -p "$logs"
failed=()
summary=()
for t in "${targets[@]}"; do
    corpus=$root/fuzz/corpus/$t
    mkdir -p "$corpus" "$root/fuzz/artifacts/$t"
    seeds "$t" | while read -r f; do cp -n "$f" "$corpus/" 2>/dev/null || true; done
    before=$(find "$root/fuzz/artifacts/$t" -type f | wc -l)
    touch "$logs/$t.start"
    echo "== fuzzing $t for $seconds s (corpus: $(ls "$corpus" | wc -l) files)"
    status=0
    fuzz run --sanitizer "$sanitizer" "$t" "$corpus" -- \
        -max_total_time="$seconds" -timeout="$timeout" -malloc_limit_mb="$malloc_limit" \
        -rss_limit_mb="$rss_limit" -print_final_stats=1 -artifact_prefix="$root/fuzz/artifacts/$t/" \
        >"$logs/$t.log" 2>&1 || status=$?
    grep -E '^#[0-9]+[[:space:]]+(INITED|DONE|NEW|REDUCE|pulse)' "$logs/$t.log" | tail -n 2 || true
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$logs/$t.log" | tail -n 1)
    last=$(grep -E '^#[0-9]+.* cov: ' "$logs/$t.log" | tail -n 1 || true)
    cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
    ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
    after=$(find "$root/fuzz/artifacts/$t" -type f | wc -l)
    found="nothing"
    if [ "$status" != 0 ] || [ "$after" -gt "$before" ]; then
        found="FOUND (exit $status): $(grep -E '^(==[0-9]+== ERROR|thread .* panicked|ERROR: libFuzzer|SUMMARY)' "$logs/$t.log" | head -n 3 | tr '\n' ' ')"
        echo "---- $t: the end of libFuzzer's output"
        tail -n 60 "$logs/$t.log"
        echo "---- new artifacts:"
        find "$root/fuzz/artifacts/$t" -type f -newer "$logs/$t.start" | sed 's/^/    /'
        failed+=("$t")
    fi
    summary+=("$(printf '%-5s  executions %-10s  cov %-6s  ft %-6s  corpus %-5s  %s' \
        "$t" "${execs:-?}" "${cov:-?}" "${ft:-?}" "$(ls "$corpus" | wc -l)" "$found")")
done

echo "== fuzzing summary ($seconds s per target)"
printf '%s\n' "${summary[@]}"
if [ ${#failed[@]} -gt 0 ]; then
    echo "scripts/fuzz.sh: found crashes, hangs or excessive allocations in: ${failed[*]}" >&2
    exit 1
fi
