#!/bin/sh
# volmorph edit stops on SIGINT or SIGTERM at any moment of its life (issue 60):
#   1. during start-up (reading, voxelizing the sides, binding, printing the URL, starting to
#      listen), ROUNDS times with the signal at delays spread over the start-up from the moment
#      its handlers are installed, while two busy loops load the machine: each time it ends, 130
#      before it serves and 0 after;
#   2. while an in-between is morphed (sdf mode, exact warp, fine voxels: seconds a frame): a state
#      request and a save are answered meanwhile (the morph holds no lock on the document), then
#      SIGINT ends the morph (503) and the editor (0).
# It asserts no time and reads no clock (tests/bench/stop_latency.sh runs it to record the
# latencies): an editor still running 30 s x SLOWNESS after the signal has hung.
# usage: edit_stop.sh VOLMORPH SOURCE_DIR [SLOWNESS [ROUNDS]]
set -eu
. "$(dirname "$0")/lib.sh"
slowness=${3:-1}
rounds=${4:-10}
command -v curl >/dev/null || { echo "curl is missing (tools/install-deps.sh installs it)"; exit 1; }
default_scene "$out/scene.toml"
load=""
trap 'for p in $load; do kill "$p" 2>/dev/null; done; rm -rf "$out"' EXIT

# ends PID SIGNAL: waits until PID has ended (a hang fails); sets status.
ends() {
    latency_start
    i=0
    while kill -0 "$1" 2>/dev/null && [ "$(awk '/^State:/ { print $2 }' "/proc/$1/status" 2>/dev/null)" != Z ]; do
        i=$((i + 1))
        [ $i -le $((slowness * 3000)) ] || { kill -9 "$1"; echo "volmorph edit hung after SIG$2"; cat "$out/edit.err"; exit 1; }
        sleep 0.01
    done
    set +e
    wait "$1"
    status=$?
    set -e
    latency_record "editor during start-up, under load"
}

# 1. Start-up, under load: the signal 0 to 2 s (x SLOWNESS) after the handlers are installed, which
#    spans this start-up (0.5-1.5 s in a release build here, loaded or not) and some serving.
start_editor "$out/scene.toml" --resolution 96 -q
stop_editor "$slowness"
for _ in 1 2; do (while :; do :; done) & load="$load $!"; done
round=0
served=0
while [ $round -lt "$rounds" ]; do
    delay=$(awk -v r="$round" -v n="$rounds" -v s="$slowness" 'BEGIN { printf "%.2f", 2.0 * s * r / (n - 1) }')
    signal=TERM
    [ $((round % 2)) -eq 1 ] && signal=INT
    "$volmorph" edit "$out/scene.toml" --resolution 96 -q >"$out/edit.out" 2>"$out/edit.err" &
    pid=$!
    wait_caught "$pid"
    sleep "$delay"
    kill -s "$signal" "$pid" 2>/dev/null || true
    ends "$pid" "$signal"
    case $status in
        130) ;;
        0) served=$((served + 1)) ;;
        *) echo "round $round: SIG$signal after $delay s: exit status $status"; cat "$out/edit.err"; exit 1 ;;
    esac
    if [ "$status" -eq 130 ] && [ -s "$out/edit.out" ] && ! grep -q interrupted "$out/edit.err"; then
        echo "round $round: 130 without a message"; cat "$out/edit.err"; exit 1
    fi
    round=$((round + 1))
done
for p in $load; do kill "$p"; done
load=""
echo "start-up: $rounds signals under load, every one ended it ($served after it served)"

# 2. A slow frame. Exact warp, sdf mode, 320 voxels across: the first in-between sets up the
#    extended distances and morphs for seconds.
sed 's|^tolerance = .*|tolerance = 0|' "$out/scene.toml" >"$out/slow.toml"
grep -q '^mode = "sdf"' "$out/slow.toml" || { echo "the default scene is not in sdf mode any more"; exit 1; }
start_editor "$out/slow.toml" --resolution 320 -q
H="X-Volmorph-Token: $token"
curl -s -o "$out/morph.body" -w '%{http_code}' -H "$H" "$base/api/mesh?of=morph&t=0.5" >"$out/morph.code" &
morph=$!
sleep 0.5
kill -0 "$morph" 2>/dev/null || { echo "the morph ended within 0.5 s: nothing tested"; exit 1; }
code=$(curl -s -o "$out/state" -w '%{http_code}' --max-time $((20 * slowness)) -H "$H" "$base/api/state")
[ "$code" = 200 ] || { echo "state during the morph: $code"; exit 1; }
code=$(curl -s -o "$out/saved" -w '%{http_code}' --max-time $((20 * slowness)) -H "$H" -H "Content-Type: application/json" --data '{}' "$base/api/save")
[ "$code" = 200 ] || { echo "save during the morph: $code"; cat "$out/saved"; exit 1; }
kill -0 "$morph" 2>/dev/null || { echo "the morph had ended before the state and the save were answered: nothing tested"; exit 1; }
stop_editor "$slowness" INT "editor during a slow frame's morph"
wait "$morph" || true
code=$(cat "$out/morph.code")
case $code in 503|000) ;; *) echo "the morph answered $code after SIGINT"; exit 1 ;; esac
echo "during a slow frame's morph: state and save answered, SIGINT ended the morph ($code) and the editor"
