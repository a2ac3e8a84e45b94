#!/bin/sh
# Builds the libFuzzer targets with clang (ASan, UBSan, coverage) in build-fuzz/ and runs each for a
# bounded time from a seed corpus (scenes/, tests/bad/, small meshes). Fails on any crash,
# sanitizer report, leak, timeout (a hang: one input over 10 s) or out-of-memory; the input that
# did it is kept under build-fuzz/findings/.
# usage: tests/fuzz/run.sh [SECONDS per target, default 60]
set -eu
cd "$(dirname "$0")/../.."
seconds=${1:-60}
build=build-fuzz
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_CXX_COMPILER=clang++ \
      -DVOLMORPH_SANITIZE=address,undefined,fuzzer-no-link -DVOLMORPH_BUILD_FUZZERS=ON \
      -DVOLMORPH_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" --parallel "$(nproc)" --target volmorph_fuzz_scene volmorph_fuzz_mesh \
    volmorph_fuzz_editor

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/scene" "$work/mesh" "$work/editor" "$build/findings"
cp scenes/*.toml tests/bad/*.toml "$work/scene/"
# Mesh seeds: the extension byte (0 obj, 1 ply, 2 stl, 3 off, 4 gltf) followed by the file.
i=0
for f in tests/data/meshes/* tests/data/stl-models-broken/*.stl scenes/meshes/cube.obj scenes/meshes/sphere.obj; do
    case "$f" in *.obj) b='\000' ;; *.ply) b='\001' ;; *.stl) b='\002' ;; *.off) b='\003' ;; *.gltf) b='\004' ;; *) continue ;; esac
    [ "$(wc -c <"$f")" -le 200000 ] || continue
    { printf "$b"; cat "$f"; } >"$work/mesh/seed$i"
    i=$((i + 1))
done

# Editor seeds: the action byte (0 set, 1 add, 2 duplicate, 3 delete, 4 undo) and a request body.
printf '\000{"key": "pair[1].target.origin", "value": [1.2, 0.1, 0]}' >"$work/editor/set"
printf '\000{"key": "pair[1].source.axes", "value": [[0, 1, 0], [-1, 0, 0]]}' >"$work/editor/axes"
printf '\000{"key": "pair[1].type", "value": "segment"}' >"$work/editor/type"
printf '\001{"type": "box", "source": {"origin": [0, 0, 0], "axes": [[1, 0, 0], [0, 1, 0]], "scale": 0.5}, "target": {"origin": [1, 0, 0]}}' >"$work/editor/add"
printf '\002{"index": 1}' >"$work/editor/duplicate"
printf '\003{"index": 1}' >"$work/editor/delete"
printf '\004{}' >"$work/editor/undo"

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
export LSAN_OPTIONS=suppressions=$PWD/tests/fuzz/lsan.supp:print_suppressions=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
for target in scene mesh editor; do
    echo "fuzz: $target for ${seconds} s"
    if ! "$build/tests/fuzz/volmorph_fuzz_$target" "$work/$target" -max_total_time="$seconds" -timeout=10 \
            -rss_limit_mb=4096 -max_len=65536 -print_final_stats=1 \
            -artifact_prefix="$build/findings/$target-" >"$work/$target.log" 2>&1; then
        echo "fuzz: $target FAILED"; tail -60 "$work/$target.log"; status=1
    else
        grep -E "stat::number_of_executed_runs|stat::new_units_added" "$work/$target.log" | sed "s/^/  /"
    fi
done
exit $status
