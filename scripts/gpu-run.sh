#!/usr/bin/env bash
# The GPU experiments on a lent GPU machine, in one call (issue 6; ../shared/GPU.md).
#
#   scripts/gpu-run.sh pack            here: build the release binary and pack it, the models the
#                                      GPU specs read and the Vulkan loader packages into .gpu-run/
#   bash scripts/gpu-run.sh remote     there (the `device` tool, carrying .gpu-run): install the
#                                      loader, use the NVIDIA driver, run every GPU spec and the
#                                      backend benchmark, and leave the results in $OUT
#   scripts/gpu-run.sh unpack DIR      here: copy the CSVs from DIR into results/ and redraw the
#                                      figures (they name the GPU and driver in every row)
#
# A GPU spec is one whose backend is "gpu", whose caches list "gpu", or that renders. The machine there cannot
# reach the network and does not see ../shared, so everything travels in .gpu-run (under 64 MiB).
set -euo pipefail
cd "$(dirname "$0")/.."

pack_dir=.gpu-run
gpu_specs() { grep -lE '^backend *= *"gpu"|^caches *=.*"gpu"|^render *=' experiments/*.toml | xargs -n1 basename | sed 's/\.toml$//'; }

pack() {
    local data=${TRIORDER_DATA:-../shared/data}
    [ -d "$data/models" ] || { echo "error: no models under $data (set TRIORDER_DATA)" >&2; exit 2; }
    cargo build --release --locked
    rm -rf "$pack_dir" && mkdir -p "$pack_dir/data/models" "$pack_dir/debs" /tmp/gpu-run-apt/partial
    strip -o "$pack_dir/triorder" target/release/triorder
    # The models every GPU spec and the benchmark name.
    local specs
    specs=$(gpu_specs | sed 's#^#experiments/#; s#$#.toml#')
    for model in $(grep -ho 'models/[A-Za-z0-9_.-]*' $specs | sort -u) models/happy_buddha_100k.obj; do
        cp "$data/$model" "$pack_dir/data/models/"
    done
    # The Vulkan loader and the GL libraries the NVIDIA driver links against (GPU.md's recipe).
    local apt=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/gpu-run-apt)
    apt-get "${apt[@]}" update -qq
    (cd "$pack_dir/debs" && apt-get "${apt[@]}" download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
    du -sh "$pack_dir"
    echo "now run, through the device tool: bash scripts/gpu-run.sh remote   (carry: $pack_dir)"
}

remote() {
    : "${OUT:?remote runs on the device machine, which sets OUT}"
    for deb in "$pack_dir"/debs/*.deb; do dpkg -x "$deb" /; done
    ldconfig
    export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
    export XDG_RUNTIME_DIR=/tmp TRIORDER_DATA=$PWD/$pack_dir/data
    local bin=$pack_dir/triorder
    nvidia-smi --query-gpu=name,driver_version --format=csv >"$OUT/gpu.txt" 2>&1 || true
    "$bin" bench --only backends --mesh models/happy_buddha_100k.obj --reps 11 | tee "$OUT/bench-backends.txt"
    for spec in $(gpu_specs); do
        "$bin" run "experiments/$spec.toml" && cp "results/$spec.csv" "$OUT/"
    done
    # The CPU/GPU cross-check on real meshes, at the resolution the papers use.
    "$bin" eval models/happy_buddha_100k.obj -m input -m nehab --views ico:162 --res 512 --backend cpu --json >"$OUT/cross-check.jsonl"
    "$bin" eval models/happy_buddha_100k.obj -m input -m nehab --views ico:162 --res 512 --backend gpu --json >>"$OUT/cross-check.jsonl"
}

unpack() {
    local from=${1:?unpack needs the folder the results came back to}
    for csv in "$from"/*.csv; do
        local id
        id=$(basename "$csv" .csv)
        cp "$csv" "results/$id.csv"
        cargo run --release --locked -- plot "experiments/$id.toml"
    done
    cat "$from"/bench-backends.txt "$from"/gpu.txt 2>/dev/null || true
}

case "${1:-}" in
    pack) pack ;;
    remote) remote ;;
    unpack) unpack "${2:-}" ;;
    *) sed -n '2,13p' "$0" >&2; exit 2 ;;
esac
