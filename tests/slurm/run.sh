#!/bin/sh
# Integration test on a real, single-node Slurm: installs slurm-wlm and munge when missing (root
# only), starts munged, slurmctld and slurmd on localhost from a generated slurm.conf in a
# temporary folder, renders the analytic scene through tools/farm-slurm.sh (3 array tasks), requeues
# one task in the middle of a frame, and checks that every frame equals a local run pixel for pixel,
# that no partial file is left, and that the finish job wrote the contact sheet. Every process it
# started is stopped at the end. Exit 77 (CTest: skipped) with a message where Slurm cannot be
# installed.
# usage: tests/slurm/run.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1 source=$2

skip() { echo "SKIPPED: $*"; exit 77; }
if ! command -v slurmctld >/dev/null 2>&1 || ! command -v munged >/dev/null 2>&1; then
    [ "$(id -u)" = 0 ] || skip "slurm-wlm is not installed and installing it needs root"
    command -v apt-get >/dev/null 2>&1 || skip "slurm-wlm is not installed and there is no apt-get"
    { DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null 2>&1 ||
      { apt-get update -qq >/dev/null 2>&1 &&
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null 2>&1; }; } \
        || skip "apt-get could not install slurm-wlm and munge"
fi
[ "$(id -u)" = 0 ] || skip "the daemons are started as root (SlurmUser=root) in this test"

T=$(mktemp -d /tmp/volmorph-slurm.XXXXXX)
chmod 755 "$T"
export SLURM_CONF="$T/slurm.conf"
cleanup() {
    set +e
    scontrol shutdown >/dev/null 2>&1
    for f in slurmctld slurmd munged; do
        [ -f "$T/$f.pid" ] && kill "$(cat "$T/$f.pid")" 2>/dev/null
    done
    sleep 2
    for f in slurmctld slurmd munged; do
        [ -f "$T/$f.pid" ] && kill -9 "$(cat "$T/$f.pid")" 2>/dev/null
    done
    pkill -9 -f "$T/slurm.conf" 2>/dev/null
    left=$(pgrep -a -f "$T" | grep -v pgrep)
    [ -z "$left" ] || echo "processes left: $left"
    rm -rf "$T"
}
trap cleanup EXIT

fail() { echo "FAILED: $*"; for f in "$T"/*.log "$T"/scene/slurm-logs/*.log; do [ -f "$f" ] && { echo "== $f"; tail -20 "$f"; }; done; exit 1; }

# munge with its own key and socket, so that a system munge (if any) is left alone.
mkdir -p "$T/munge" "$T/state" "$T/spool" "$T/scene"
dd if=/dev/urandom of="$T/munge/munge.key" bs=1024 count=1 2>/dev/null
chmod 700 "$T/munge"; chmod 400 "$T/munge/munge.key"
munged --force --key-file="$T/munge/munge.key" --socket="$T/munge/munge.sock" --pid-file="$T/munged.pid" \
    --log-file="$T/munged.log" --seed-file="$T/munge/seed" || fail "munged did not start"

host=$(hostname -s)
port=$((20000 + $$ % 20000))
# A requeued task waits for its old credential to expire (cred_expire, 120 s by default), for KillWait
# (30 s) and for a scheduler pass (sched_interval, 60 s): 170 s of an idle test at the defaults; 20 s here.
cat >"$SLURM_CONF" <<EOF
ClusterName=volmorphtest
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$T/munge/munge.sock,cred_expire=10
KillWait=5
CredType=cred/munge
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/builtin
SchedulerParameters=sched_interval=2
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
SwitchType=switch/none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=volmorph Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -f "$SLURM_CONF" || fail "slurmctld did not start"
slurmd -f "$SLURM_CONF" || fail "slurmd did not start"
i=0
until sinfo -h -o %t 2>/dev/null | grep -q idle; do
    i=$((i + 1)); [ $i -lt 60 ] || fail "the node never became idle: $(sinfo 2>&1)"
    sleep 1
done
echo "slurm: $(sinfo -h -o '%P %D %t %c CPUs')"

# The analytic scene, frames large enough (about a second each) to requeue a task inside one.
sed "s|meshes/|$source/scenes/meshes/|; s|resolution = \[256, 128\]|resolution = [1024, 512]|" \
    "$source/scenes/sphere-to-box.toml" >"$T/scene/scene.toml"
VOLMORPH_CACHE="$T/local-cache" "$volmorph" render "$T/scene/scene.toml" -o "$T/local/f.####.exr" -q

sh "$source/tools/farm-slurm.sh" "$T/scene/scene.toml" --chunk 2 --output "$T/frames/f.####.exr" \
    --cache "$T/cache" --time 10 --volmorph "$volmorph" >"$T/submit.out" || fail "farm-slurm.sh failed"
cat "$T/submit.out"
render_job=$(sed -n 's/^render *job \([0-9]*\).*/\1/p' "$T/submit.out")
[ -n "$render_job" ] || fail "no render job id"

# Requeue task 1 while it is inside a frame: Slurm stops it (SIGTERM, then SIGKILL) and runs it again.
i=0
until grep -q "^frame 2 " "$T/scene/slurm-logs/render-${render_job}_1.log" 2>/dev/null \
      || grep -q "^frame 3 " "$T/scene/slurm-logs/render-${render_job}_1.log" 2>/dev/null; do
    if grep -q "ALF_PROGRESS 0%" "$T/scene/slurm-logs/render-${render_job}_1.log" 2>/dev/null; then break; fi
    i=$((i + 1)); [ $i -lt 300 ] || fail "task 1 never started"
    sleep 0.2
done
sleep 0.5
scontrol requeue "${render_job}_1" || fail "scontrol requeue refused"
echo "requeued task 1 of job $render_job while it ran"

i=0
while [ -n "$(squeue -h 2>/dev/null)" ]; do
    i=$((i + 1)); [ $i -lt 600 ] || fail "jobs still queued after 600 s: $(squeue)"
    sleep 1
done

restarts=$(scontrol show job "${render_job}_1" 2>/dev/null | sed -n 's/.*Restarts=\([0-9]*\).*/\1/p' | head -1)
[ "${restarts:-0}" -ge 1 ] || fail "task 1 was not run again after the requeue (Restarts=${restarts:-?})"
[ -f "$T/frames/contact-sheet.png" ] || fail "the finish job wrote no contact sheet"
for n in 0000 0001 0002 0003 0004; do
    "$volmorph" diff -q --fail 0 "$T/local/f.$n.exr" "$T/frames/f.$n.exr" || fail "frame $n differs from the local run"
done
partial=$(ls "$T/frames" | grep partial || true)
[ -z "$partial" ] || fail "partial files left: $partial"
tasks=$(ls "$T"/scene/slurm-logs/render-"${render_job}"_*.log | wc -l)
[ "$tasks" = 3 ] || fail "expected 3 array tasks, saw $tasks logs"
echo "slurm: 3 array tasks (one requeued mid-frame) gave the frames of a local run bit for bit"
