# Sourced by CLI tests called as `test.sh VOLMORPH SOURCE_DIR`: sets volmorph and src, makes a
# scratch folder $out removed on exit, and defines expect_files.
volmorph=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# wait_caught PID: until the process catches SIGINT and SIGTERM (bits 2 and 15 of SigCgt), for at
# most 60 s. Before that a background job of a non-interactive shell ignores SIGINT, and SIGTERM
# kills it outright: a signal would test nothing.
wait_caught() {
    i=0
    until mask=$(awk '/^SigCgt:/ { print $2 }' "/proc/$1/status" 2>/dev/null) && [ -n "$mask" ] &&
        [ $((0x$mask & 0x4002)) -eq $((0x4002)) ]; do
        i=$((i + 1))
        [ $i -lt 3000 ] || { echo "no SIGINT and SIGTERM handlers after 60 s"; exit 1; }
        sleep 0.02
    done
}

# expect_files DIR "a b c": DIR holds exactly these files (ls order), or the test fails saying
# what it holds.
expect_files() {
    held=$(ls "$1" | tr '\n' ' ')
    [ "$held" = "$2 " ] || { echo "$1 holds: $held(expected $2)"; exit 1; }
}

# volume_scene VOLUME [TABLES]: writes $out/scene.toml, the volume VOLUME into the cube mesh
# (moved to x = 3, clear of it), with TABLES (TOML text) appended.
volume_scene() {
    printf '[source]\nvolume = "%s"\n[target]\nmesh = "%s"\ntransform = { translate = [3, 0, 0] }\n%s\n' \
        "$1" "$src/tests/data/meshes/cube.obj" "${2:-}" >"$out/scene.toml"
}

# start_editor SCENE [ARGS]: runs `volmorph edit SCENE ARGS` in the background with its stdout in
# $out/edit.out and stderr in $out/edit.err; sets editor_pid, url (the first line it prints), base
# (http://127.0.0.1:PORT) and token. Fails if no URL comes within 300 s (a sanitizer build
# voxelizes slowly).
start_editor() {
    scene=$1
    shift
    # An earlier run's URL must not be read for this one's (the redirection below truncates the
    # file only once the background shell gets to it).
    rm -f "$out/edit.out"
    "$volmorph" edit "$scene" "$@" >"$out/edit.out" 2>"$out/edit.err" &
    editor_pid=$!
    i=0
    while [ ! -s "$out/edit.out" ]; do
        kill -0 "$editor_pid" 2>/dev/null || { echo "volmorph edit exited:"; cat "$out/edit.err"; exit 1; }
        i=$((i + 1))
        [ $i -lt 3000 ] || { echo "volmorph edit printed no URL"; exit 1; }
        sleep 0.1
    done
    url=$(head -n 1 "$out/edit.out")
    base=${url%%/?token=*}
    token=${url##*token=}
}

# latency_start / latency_record WHAT: only when tests/bench/stop_latency.sh runs a test (it sets
# STOP_LATENCY_LOG), the seconds from the start to now, appended to that log as "SECONDS WHAT".
# Tests themselves read no clock: they assert behaviour, and a loaded machine answers later.
latency_start() { [ -z "${STOP_LATENCY_LOG:-}" ] || latency_t0=$(date +%s.%N); }
latency_record() {
    [ -z "${STOP_LATENCY_LOG:-}" ] ||
        awk -v a="$latency_t0" -v b="$(date +%s.%N)" -v w="$1" 'BEGIN { printf "%.3f %s\n", b - a, w }' >>"$STOP_LATENCY_LOG"
}

# stop_editor SLOWNESS [SIGNAL [WHAT]]: SIGINT (or SIGNAL) to the editor, which must exit 0 (a run
# still going 30 s x SLOWNESS after the signal has hung); WHAT names its latency for the benchmark.
stop_editor() {
    latency_start
    kill -s "${2:-INT}" "$editor_pid"
    polls=$(($1 * 3000))
    i=0
    while kill -0 "$editor_pid" 2>/dev/null && [ "$(awk '/^State:/ { print $2 }' "/proc/$editor_pid/status" 2>/dev/null)" != Z ]; do
        i=$((i + 1))
        [ $i -le "$polls" ] || { echo "volmorph edit still running $(($1 * 30)) s after SIG${2:-INT} (hung)"; kill -9 "$editor_pid"; exit 1; }
        sleep 0.01
    done
    wait "$editor_pid" || { echo "volmorph edit exited $? on SIG${2:-INT}"; cat "$out/edit.err"; exit 1; }
    [ -z "${3:-}" ] || latency_record "$3"
}

# default_scene DEST: the default scene with its paths made absolute.
default_scene() {
    sed -e "s|\"meshes/|\"$src/scenes/meshes/|" -e "s|\"skies/|\"$src/scenes/skies/|" \
        "$src/scenes/bunny-to-knot.toml" >"$1"
}
