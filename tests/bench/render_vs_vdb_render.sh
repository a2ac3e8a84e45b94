#!/bin/sh
# volmorph render-vdb against OpenVDB's vdb_render on the same grid, camera and light, with shadows,
# in one run: median wall time of RUNS renders each, and each one's alpha error against a converged
# alpha reference made by vdb_render at a tiny step and -cutoff 1e-7 (alpha does not depend on
# shadows, so the reference may use a coarse shadow step).
# usage: tests/bench/render_vs_vdb_render.sh BUILD_DIR [RUNS]     (needs vdb_render and oiiotool)
set -eu
build=$1
runs=${2:-5}
volmorph=$build/bin/volmorph
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
root=$(cd "$(dirname "$0")/../.." && pwd)

# The bunny as fog at 256 voxels across (voxel 0.0387 world units); extinction 1 per world unit,
# albedo 0.8: vdb_render's coefficients are per voxel.
"$volmorph" voxelize "$root/scenes/meshes/bunny.obj" -o "$out/bunny.vdb" --resolution 256 -q
absorb=0.0077401   # 1 * 0.2 * 0.0387005
scatter=0.0309604  # 1 * 0.8 * 0.0387005
camera="-translate 0,5,25 -lookat 0,4.8,0 -fov 40 -res 640x360"
vdb="vdb_render $out/bunny.vdb $camera -absorb $absorb,$absorb,$absorb -scatter $scatter,$scatter,$scatter
     -light 0.3,0.7,0.6,1,1,1 -name density -cutoff 1e-7"
vm="$volmorph render-vdb $out/bunny.vdb --translate 0,5,25 --lookat 0,4.8,0 --fov 40 --res 640x360
    --extinction 1 --albedo 0.8 --light 0.3,0.7,0.6 --samples 1 --grid density --float"

$vdb "$out/ref.exr" -step 0.05 -shadowstep 20 >/dev/null

median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
time_runs() { # command... ; prints the median wall time in seconds
    for i in $(seq "$runs"); do
        start=$(date +%s.%N); "$@" >/dev/null 2>&1; end=$(date +%s.%N)
        echo "$end - $start" | bc
    done | median
}
alpha_error() { oiiotool "$1" --ch A "$out/ref.exr" --ch A --diff 2>&1 | grep -E "Mean error|Max error" | tr -s ' ' | tr '\n' ' '; }

t_vdb=$(time_runs $vdb "$out/vdb.exr")
oiiotool --info -v "$out/vdb.exr" | grep -i -E "channel|format" | head -3
t_vm=$(time_runs $vm -o "$out/vm.exr")
echo "vdb_render (step 1, shadow step 3): median ${t_vdb} s; alpha: $(alpha_error "$out/vdb.exr")"
echo "volmorph   (step 0.5, shadows cached every 2 voxels, step 1): median ${t_vm} s; alpha: $(alpha_error "$out/vm.exr")"
echo "speed-up: $(echo "scale=2; $t_vdb / $t_vm" | bc)x"
