#!/bin/sh
# Renders a scene's sequence on a Slurm cluster as a job array. Submits three jobs:
#   1. voxelize: `volmorph cache` fills the shared voxel cache once;
#   2. render (a job array, after 1): task I renders chunk I, the frames `volmorph frames SCENE
#      --chunk N --task I` prints (the last chunk takes the remainder), with --skip-existing, so a
#      requeued or rerun task only redoes missing frames; frames are written atomically, and a task
#      gets SIGTERM 60 s before its time limit, on which volmorph stops cleanly (no partial file);
#   3. finish (after every task of 2 succeeded): every frame must read back; writes the contact sheet.
# usage: tools/farm-slurm.sh SCENE [--chunk N] [--partition P] [--max-running K] [--output PATTERN]
#            [--cache DIR] [--time MINUTES] [--volmorph PATH] [--frames SPEC] [--dry-run]
# SCENE, PATTERN and DIR must be on storage every node sees. --dry-run prints the sbatch scripts.
set -eu

usage() { sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
die() { echo "farm-slurm: $*" >&2; exit 1; }

[ $# -ge 1 ] || usage
scene=$1; shift
chunk=10 partition="" max_running="" output="" cache="" minutes=60 dry_run=0 frames=""
volmorph=$(cd "$(dirname "$0")/.." && pwd)/build/bin/volmorph
while [ $# -gt 0 ]; do
    case "$1" in
        --chunk) chunk=$2; shift 2 ;;
        --partition) partition=$2; shift 2 ;;
        --max-running) max_running=$2; shift 2 ;;
        --output|-o) output=$2; shift 2 ;;
        --cache) cache=$2; shift 2 ;;
        --time) minutes=$2; shift 2 ;;
        --volmorph) volmorph=$2; shift 2 ;;
        --frames) frames=$2; shift 2 ;;
        --dry-run) dry_run=1; shift ;;
        -h|--help) usage ;;
        *) echo "farm-slurm: unknown argument $1" >&2; usage ;;
    esac
done
case "$chunk" in ''|*[!0-9]*|0) die "--chunk: expected a positive number of frames, got '$chunk'" ;; esac
case "$minutes" in ''|*[!0-9]*|0) die "--time: expected a positive number of minutes, got '$minutes'" ;; esac
[ -z "$max_running" ] || case "$max_running" in *[!0-9]*|0) die "--max-running: expected a positive number" ;; esac
[ -x "$volmorph" ] || die "$volmorph: no volmorph program (build it, or give --volmorph PATH)"
[ -f "$scene" ] || die "$scene: scene file not found"

absolute() { case "$1" in /*) echo "$1" ;; *) echo "$PWD/$1" ;; esac; }
scene=$(absolute "$scene")
volmorph=$(absolute "$volmorph")
[ -z "$cache" ] && cache=$(dirname "$scene")/.volmorph-cache
cache=$(absolute "$cache")
frame_flag=""
[ -z "$frames" ] || frame_flag="--frames $frames"
# The scene is checked here, before anything is submitted: a typo fails now, not on a node.
"$volmorph" check "$scene" >/dev/null
# shellcheck disable=SC2086
tasks=$("$volmorph" frames "$scene" $frame_flag --chunk "$chunk" --count)
out_flag=""
if [ -n "$output" ]; then
    from=$(absolute "$output")
    out_flag="-o '$from'"
else
    from=$("$volmorph" frames "$scene" --output-pattern)
fi
sheet=$(dirname "$from")/contact-sheet.png
logs=$(dirname "$scene")/slurm-logs
part_line=""
[ -z "$partition" ] || part_line="#SBATCH --partition=$partition"
array="0-$((tasks - 1))"
[ -z "$max_running" ] || array="$array%$max_running"

voxelize_script="#!/bin/sh
#SBATCH --job-name=volmorph-voxelize
#SBATCH --output=$logs/voxelize-%j.log
#SBATCH --time=$minutes
$part_line
exec '$volmorph' cache '$scene' --cache '$cache'"

render_script="#!/bin/sh
#SBATCH --job-name=volmorph-render
#SBATCH --array=$array
#SBATCH --output=$logs/render-%A_%a.log
#SBATCH --time=$minutes
#SBATCH --requeue
#SBATCH --signal=B:TERM@60
$part_line
# Task \$SLURM_ARRAY_TASK_ID renders chunk \$SLURM_ARRAY_TASK_ID of $chunk frames.
frames=\$('$volmorph' frames '$scene' $frame_flag --chunk $chunk --task \"\$SLURM_ARRAY_TASK_ID\") || exit 1
echo \"task \$SLURM_ARRAY_TASK_ID: frames \$frames\"
exec '$volmorph' render '$scene' --frames \"\$frames\" $out_flag --skip-existing --cache '$cache'"

finish_script="#!/bin/sh
#SBATCH --job-name=volmorph-finish
#SBATCH --output=$logs/finish-%j.log
#SBATCH --time=$minutes
$part_line
# Every frame must read back; then the contact sheet.
exec '$volmorph' preview '$scene' --contact-sheet $frame_flag --from '$from' -o '$sheet'"

if [ $dry_run = 1 ]; then
    printf '# 1. voxelize\n%s\n\n# 2. render: %s tasks (sbatch --dependency=afterok:<1>)\n%s\n\n' \
        "$voxelize_script" "$tasks" "$render_script"
    printf '# 3. finish (sbatch --dependency=afterok:<2>)\n%s\n' "$finish_script"
    exit 0
fi

command -v sbatch >/dev/null 2>&1 || die "sbatch not found: is this a Slurm submit host?"
mkdir -p "$logs" "$cache"
voxelize_job=$(echo "$voxelize_script" | sbatch --parsable) || die "sbatch refused the voxelize job"
render_job=$(echo "$render_script" | sbatch --parsable --dependency="afterok:${voxelize_job%%;*}") \
    || die "sbatch refused the render array"
finish_job=$(echo "$finish_script" | sbatch --parsable --dependency="afterok:${render_job%%;*}") \
    || die "sbatch refused the finish job"
echo "voxelize job ${voxelize_job%%;*}"
echo "render   job ${render_job%%;*} ($tasks tasks of up to $chunk frames)"
echo "finish   job ${finish_job%%;*} (contact sheet: $sheet)"
echo "logs in $logs; rerun failures with: scontrol requeue ${render_job%%;*}_<task>"
