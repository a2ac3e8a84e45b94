#!/bin/sh
# Proves that two builds of volmorph give the same bits: a refactoring must not change any output.
#
#   tests/identity/bit_identity.sh BASE [NEW] [--quick] [--keep] [--base-build DIR] [--new-build DIR]
#
# BASE and NEW are commits (NEW defaults to the working tree as it is, uncommitted changes included).
# Each is built in Release with the benchmarks, in build-identity/ beside the checkout (a commit in a
# git worktree of its own; kept between runs, so a second run only rebuilds what changed, with ccache).
# --base-build DIR uses an existing Release build of BASE with the benchmarks instead (it needs
# DIR/bin/volmorph and DIR/tests/bench/volmorph_bench_warp), to spare a 2-core machine a full build;
# --new-build DIR likewise for NEW (a build of the working tree, say).
# Then, for each build, at 1 thread (taskset to one core: TBB follows the affinity mask, and
# --threads 1) and at 2 threads, it records:
#   - points_hash of the approximated warp (tests/bench/warp_bench.cpp) at 1, 4, 16 and 64 pairs;
#   - every grid of every frame `volmorph morph` writes for each scene in scenes/ (tests/identity/
#     vdb_hash.cpp: every leaf and tile, the transform and the background);
#   - the pixels of every frame `volmorph render` writes for those scenes (iinfo --hash: SHA-1 of the
#     pixel values, not of the file, whose metadata holds the render time).
# The four manifests (2 builds x 2 thread counts) must be equal line for line; a difference is
# printed and the exit status is 1. --quick takes the first, middle and last frame of each scene
# instead of every frame. The scenes are the checkout's, for both builds. Manifests and outputs are
# left in build-identity/run/ with --keep.
set -eu

usage() { echo "usage: tests/identity/bit_identity.sh BASE [NEW] [--quick] [--keep] [--base-build DIR] [--new-build DIR]" >&2; exit 2; }
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
base="" new="" quick=0 keep=0 base_build="" new_build=""
while [ $# -gt 0 ]; do
    a=$1
    shift
    case "$a" in
        --quick) quick=1 ;;
        --base-build) [ $# -gt 0 ] || usage; base_build=$(cd "$1" && pwd); shift ;;
        --new-build) [ $# -gt 0 ] || usage; new_build=$(cd "$1" && pwd); shift ;;
        --keep) keep=1 ;;
        -*) usage ;;
        *) if [ -z "$base" ]; then base=$a; elif [ -z "$new" ]; then new=$a; else usage; fi ;;
    esac
done
[ -n "$base" ] || usage
work=$root/build-identity
mkdir -p "$work"
jobs=$(nproc 2>/dev/null || echo 2)

# build SPEC -> prints the build folder. SPEC is a commit, or "" for the working tree.
build() {
    if [ -z "$1" ]; then
        src=$root
        dir=$work/worktree
    else
        sha=$(git rev-parse --verify "$1^{commit}") || { echo "bit_identity: no commit $1" >&2; exit 2; }
        src=$work/src-$sha
        dir=$work/build-$sha
        [ -d "$src" ] || git worktree add --detach "$src" "$sha" >/dev/null 2>&1
    fi
    cmake -S "$src" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVOLMORPH_BUILD_TESTS=OFF \
          -DVOLMORPH_BUILD_BENCHMARKS=ON >/dev/null
    cmake --build "$dir" --parallel "$jobs" --target volmorph_cli volmorph_bench_warp >&2
    echo "$dir"
}

# The hasher, from this checkout (it reads files; it does not depend on either build).
hasher=$work/vdb_hash
if [ ! -x "$hasher" ] || [ "$root/tests/identity/vdb_hash.cpp" -nt "$hasher" ]; then
    c++ -std=c++17 -O2 "$root/tests/identity/vdb_hash.cpp" -o "$hasher" -lopenvdb -ltbb -lImath-3_1
fi

# frames_of SCENE -> the --frames spec to use ("" for all).
frames_of() {
    [ "$quick" -eq 1 ] || { echo ""; return; }
    range=$(sed -n 's/^range *= *"\([0-9]*\)-\([0-9]*\)".*/\1 \2/p' "$1" | head -n 1)
    set -- $range
    echo "$1,$(( ($1 + $2) / 2 )),$2"
}

# manifest BUILD THREADS OUT: every hash of one build at one thread count, one per line.
manifest() {
    bin=$1/bin/volmorph
    threads=$2
    out=$3
    pin=""
    [ "$threads" -eq 1 ] && pin="taskset -c 0"
    files=$(dirname "$out")/files-$(basename "$out")
    rm -rf "$files"
    mkdir -p "$files"
    : >"$out"
    $pin "$1/tests/bench/volmorph_bench_warp" --benchmark_filter='approximatedWarp/(1|4|16|64)/' \
        --benchmark_min_time=0.01 --benchmark_format=json 2>/dev/null |
        sed -n 's/.*"name": "\(approximatedWarp[^"]*\)".*/\1/p; s/.*"points_hash": \([0-9.e+]*\).*/points_hash \1/p' |
        paste -d ' ' - - >>"$out"
    if [ "$(grep -c 'points_hash [0-9]' "$out")" -ne 4 ]; then
        echo "bit_identity: $1: the warp bench gave no points_hash at 1, 4, 16 and 64 pairs" >&2
        exit 2
    fi
    for scene in scenes/*.toml; do
        name=$(basename "$scene" .toml)
        spec=$(frames_of "$scene")
        fl=""
        [ -n "$spec" ] && fl="--frames $spec"
        # shellcheck disable=SC2086
        $pin "$bin" morph "$scene" $fl --no-cache -q -o "$files/$name.morph.####.vdb"
        (cd "$files" && "$hasher" "$name".morph.*.vdb) >>"$out"
        # shellcheck disable=SC2086
        $pin "$bin" render "$scene" $fl --no-cache -q --threads "$threads" -o "$files/$name.render.####.exr"
        for f in "$files/$name".render.*.exr; do
            echo "$(basename "$f") $(iinfo --hash "$f" | sed -n 's/.*SHA-1: *//p')" >>"$out"
        done
    done
    [ "$keep" -eq 1 ] || rm -rf "$files"
}

# given DIR SPEC: DIR checked, or SPEC built.
given() {
    if [ -n "$1" ]; then
        [ -x "$1/bin/volmorph" ] && [ -x "$1/tests/bench/volmorph_bench_warp" ] ||
            { echo "bit_identity: $1 has no bin/volmorph and tests/bench/volmorph_bench_warp" >&2; exit 2; }
        echo "$1"
    else
        build "$2"
    fi
}
base_dir=$(given "$base_build" "$base")
new_dir=$(given "$new_build" "$new")
run=$work/run
rm -rf "$run"
mkdir -p "$run"
for side in base new; do
    eval dir=\$${side}_dir
    for threads in 1 2; do
        echo "bit_identity: $side ($dir), $threads thread(s)" >&2
        manifest "$dir" "$threads" "$run/$side-$threads.txt"
    done
done

status=0
lines=$(wc -l <"$run/base-1.txt")
for m in base-2 new-1 new-2; do
    if ! diff -u "$run/base-1.txt" "$run/$m.txt" >"$run/$m.diff"; then
        echo "bit_identity: $m differs from base-1:" >&2
        cat "$run/$m.diff" >&2
        status=1
    fi
done
if [ "$status" -eq 0 ]; then
    echo "bit_identity: identical: $lines hashes (warp points, grids, frame pixels), base ${base} vs ${new:-working tree}, 1 and 2 threads"
fi
[ "$keep" -eq 1 ] || rm -rf "$run"/files-*
exit "$status"
