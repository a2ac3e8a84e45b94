#!/bin/sh
# SIGTERM (what Slurm sends before a job's time limit) or SIGINT stops a run, with exit status 130
# and no file at the final name, wherever it lands, before the work would have finished (the log's
# next stage never comes):
#   1. render-vdb at 1920x1080 with 256 samples, two seconds in (fails if the frame had finished);
#   2. render-vdb while its shadow maps are built (--verbose names each stage as it starts: fails
#      unless the signal landed after "render: shadows" began and before "render: pixels" did);
#   3. render, morph and preview of a scene during a frame's morph (the exact warp on fine voxels,
#      seconds per frame; fails unless it landed after "frame 1: morph" and before the next stage),
#      and morph during its setup (each side's extended distance: fails unless it landed after
#      "morph setup" and before "frame 1: morph");
#   4. morph of a variational scene during its solve (two seconds in, fails if the frame had begun)
#      and during its frame (after "frame 1: morph").
# The test asserts no time: how soon a run stops (the promise: within 1 s) is measured by
# tests/bench/stop_latency.sh, on an idle machine, from the latencies this script records in
# $STOP_LATENCY_LOG when that is set. A run still going LIMIT x 30 s after the signal has hung.
# usage: render_interrupt.sh VOLMORPH SOURCE_DIR [LIMIT [COARSEN]]
#        LIMIT: how much slower than a release build this one is (default 1; sanitizer builds, which
#        run 5-40 times slower, pass more): it scales the waits
#        COARSEN: voxels this many times larger (default 1; sanitizer builds pass 2), so that each
#        interrupted stage still lasts seconds and the test not minutes
set -u
volmorph=$1
source_dir=$2
limit=${3:-1.0}
coarsen=${4:-1}
dir=$(mktemp -d)
pid=0
trap 'kill -9 $pid 2>/dev/null; rm -rf "$dir"' EXIT
export VOLMORPH_CACHE="$dir/cache"

fail() { echo "FAIL: $*"; [ -f "$dir/err" ] && { echo "stderr:"; cat "$dir/err"; }; exit 1; }
now() { date +%s.%N; }

# wait_for PATTERN: until the running command's stderr shows PATTERN (polled every 20 ms), for at
# most 60 s times LIMIT (a sanitizer build voxelizes the morph case's sides for over a minute).
polls=$(awk -v l="$limit" 'BEGIN { printf "%d", 3000 * (l > 1 ? l : 1) }')
wait_for() {
    i=0
    until grep -qs "$1" "$dir/err"; do
        kill -0 "$pid" 2>/dev/null || fail "the command ended before \"$1\""
        i=$((i + 1))
        [ $i -lt "$polls" ] || fail "\"$1\" never came"
        sleep 0.02
    done
}

# start PATTERN ARGS...: runs volmorph ARGS -v in the background until its log ($dir/err) shows
# PATTERN. The last command's log goes first: wait_for could otherwise read it before the shell
# truncates the file for this one, and signal a process that has no handler yet (exit 143).
start() {
    pattern=$1
    shift
    rm -f "$dir/err"
    "$volmorph" "$@" -v 2>"$dir/err" >/dev/null &
    pid=$!
    wait_for "$pattern"
}

# stop SIGNAL WHAT: sends SIGNAL, waits, and checks the exit status and the output folder; records
# the delay (never asserted: a loaded machine may take longer) and fails only on a hang.
hang=$(awk -v l="$limit" 'BEGIN { printf "%d", 3000 * (l > 1 ? l : 1) }') # polls 10 ms apart
stop() {
    [ -z "${STOP_LATENCY_LOG:-}" ] || t0=$(now) # only the benchmark reads the clock
    kill -s "$1" "$pid"
    i=0
    while kill -0 "$pid" 2>/dev/null && [ "$(awk '/^State:/ { print $2 }' "/proc/$pid/status" 2>/dev/null)" != Z ]; do
        i=$((i + 1))
        [ $i -lt "$hang" ] || { kill -9 "$pid"; fail "$2: still running $((hang / 100)) s after SIG$1 (hung)"; }
        sleep 0.01
    done
    wait "$pid"
    status=$?
    [ -z "${STOP_LATENCY_LOG:-}" ] ||
        awk -v a="$t0" -v b="$(now)" -v w="$2" 'BEGIN { printf "%.3f %s\n", b - a, w }' >>"$STOP_LATENCY_LOG"
    [ "$status" -eq 130 ] || fail "$2: exit status $status after SIG$1, expected 130"
    grep -q "interrupted; no output written" "$dir/err" || fail "$2: no message"
    left=$(ls "$dir/out" 2>/dev/null || true)
    [ -z "$left" ] || fail "$2: left files: $left"
    echo "$2: SIG$1 -> exit 130, no file"
}

# A volume whose shadow map at every voxel takes seconds to build.
"$volmorph" voxelize "$source_dir/scenes/meshes/bunny.obj" -o "$dir/bunny.vdb" --resolution $((400 / coarsen)) -q ||
    fail "voxelize"

# 1. Two seconds into a 1920x1080 frame of 256 samples.
"$volmorph" render-vdb "$dir/bunny.vdb" --grid density -o "$dir/out/frame.exr" --res 1920x1080 --samples 256 \
    2>"$dir/err" >/dev/null &
pid=$!
sleep 2
kill -0 "$pid" 2>/dev/null || fail "render-vdb had finished before the signal; nothing tested"
stop TERM "render-vdb at 1920x1080, 256 samples"

# 2. While the shadow maps are built.
start "render: shadows" render-vdb "$dir/bunny.vdb" --grid density -o "$dir/out/frame.exr" \
    --res 64x36 --samples 1 --shadow-cache 1
stop TERM "render-vdb during its shadow maps"
grep -q "render: pixels" "$dir/err" && fail "the shadow maps were done before the signal; nothing tested"

# 3. During a frame's morph: the default scene with the exact warp on voxels of 0.003 (~330 across)
#    times COARSEN.
voxel=$(awk -v c="$coarsen" 'BEGIN { print 0.003 * c }')
sed "s|meshes/|$source_dir/scenes/meshes/|; s|skies/|$source_dir/scenes/skies/|; s|^voxel_size = .*|voxel_size = $voxel|; s|^tolerance = .*|tolerance = 0|" \
    "$source_dir/scenes/bunny-to-knot.toml" >"$dir/scene.toml"
"$volmorph" cache "$dir/scene.toml" -q || fail "cache"
for command in render morph preview; do
    case $command in
        render) set -- render "$dir/scene.toml" --frames 1 -o "$dir/out/f.####.exr" ;;
        morph) set -- morph "$dir/scene.toml" --frames 1 -o "$dir/out/f.####.vdb" ;;
        preview) set -- preview "$dir/scene.toml" --frame 1 -o "$dir/out/preview.png" ;;
    esac
    start "frame 1: morph" "$@"
    signal=TERM
    [ "$command" = morph ] && signal=INT
    stop "$signal" "$command during a frame's morph"
    grep -q "render: empty-space mask" "$dir/err" && fail "$command: the morph was done before the signal"
done
start "morph setup" morph "$dir/scene.toml" --frames 1 -o "$dir/out/f.####.vdb"
sleep 0.3
stop INT "morph during its setup"
grep -q "frame 1: morph" "$dir/err" && fail "the setup was done before the signal"
# 4. The variational method: dino-to-eight-variational at 320 voxels across divided by COARSEN (its
#    solve takes seconds, and so does a frame).
sed "s|meshes/|$source_dir/scenes/meshes/|; s|^resolution = 128 |resolution = $((320 / coarsen)) |" \
    "$source_dir/scenes/dino-to-eight-variational.toml" >"$dir/variational.toml"
start voxelize morph "$dir/variational.toml" --frames 15 -o "$dir/out/v.####.vdb" --no-cache
sleep 1.5
stop INT "morph during the variational solve"
grep -q "frame 15: morph" "$dir/err" && fail "the variational solve was done before the signal"
start "frame 15: morph" morph "$dir/variational.toml" --frames 15 -o "$dir/out/v.####.vdb"
sleep 0.3
stop TERM "morph during a variational frame"
echo "every interrupt stopped with exit 130 and no file"
