#!/bin/sh
# volmorph render-vdb against OpenVDB's vdb_render on the same grids, camera and light, with
# shadows, in one run, on two volumes (the bunny as fog, the procedural cloud): median wall time of
# RUNS renders each (whole commands: start-up, reading, rendering, writing), for vdb_render at its
# defaults and at accurate settings (step 0.5, -cutoff 1e-7) and for volmorph at its
# defaults, and each one's alpha error against a converged reference made by vdb_render: the same
# density with its active topology dilated by one voxel (values unchanged, volmorph_bench_dilate:
# vdb_render's ray intersector skips the trilinear tail outside the active voxels), step 0.05 voxel,
# -cutoff 1e-14 (T < 6e-8). Alpha does not depend on shadows, so the reference uses a coarse shadow
# step. EXRs are float on both sides (vdb_render writes float), so half quantization is not counted.
# usage: tests/bench/render_vs_vdb_render.sh BUILD_DIR [RUNS]
#        BUILD_DIR configured with -DVOLMORPH_BUILD_BENCHMARKS=ON; needs vdb_render and oiiotool
set -eu
build=$1
runs=${2:-5}
volmorph=$build/bin/volmorph
dilate=$build/tests/bench/volmorph_bench_dilate
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
root=$(cd "$(dirname "$0")/../.." && pwd)

median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
time_runs() { # command... ; prints the median wall time in seconds
    for i in $(seq "$runs"); do
        start=$(date +%s.%N); "$@" >/dev/null 2>&1; end=$(date +%s.%N)
        echo "$end - $start" | bc
    done | median
}
alpha_error() { # image reference
    oiiotool "$1" --ch A "$2" --ch A --diff 2>&1 | grep -E "Mean error|Max error" | sed 's/@.*//' | tr -s ' ' | tr '\n' ' '
}

# One volume: NAME FILE VOXEL EXTINCTION CAMERA (vdb_render's flags; volmorph's are the same with
# two dashes). vdb_render's coefficients are per voxel: absorb = extinction (1 - albedo) voxel,
# scatter = extinction albedo voxel, albedo 0.8.
compare() {
    name=$1 vdb=$2 voxel=$3 extinction=$4 camera=$5
    "$dilate" "$vdb" "$out/dilated.vdb"
    absorb=$(echo "$extinction * 0.2 * $voxel" | bc -l)
    scatter=$(echo "$extinction * 0.8 * $voxel" | bc -l)
    vdb_args="$camera -absorb $absorb,$absorb,$absorb -scatter $scatter,$scatter,$scatter -light 0.3,0.7,0.6,1,1,1 -name density"
    vm_camera=$(echo "$camera" | sed 's/-\([a-z]\)/--\1/g')
    vm="$volmorph render-vdb $vdb $vm_camera --extinction $extinction --albedo 0.8 --light 0.3,0.7,0.6 --grid density --float"
    vdb_render "$out/dilated.vdb" "$out/ref.exr" $vdb_args -cutoff 1e-14 -step 0.05 -shadowstep 20 >/dev/null
    t_default=$(time_runs vdb_render "$vdb" "$out/default.exr" $vdb_args)
    t_accurate=$(time_runs vdb_render "$vdb" "$out/accurate.exr" $vdb_args -step 0.5 -cutoff 1e-7)
    # shellcheck disable=SC2086
    t_vm=$(time_runs $vm -o "$out/vm.exr")
    echo "== $name"
    echo "   vdb_render defaults (step 1, shadow step 3, cutoff 0.005): median $t_default s;" \
        "alpha $(alpha_error "$out/default.exr" "$out/ref.exr")"
    echo "   vdb_render accurate (step 0.5, shadow step 3, cutoff 1e-7): median $t_accurate s;" \
        "alpha $(alpha_error "$out/accurate.exr" "$out/ref.exr")"
    echo "   volmorph render-vdb defaults: median $t_vm s; alpha $(alpha_error "$out/vm.exr" "$out/ref.exr")"
    echo "   speed-up: $(echo "scale=2; $t_default / $t_vm" | bc)x against the defaults," \
        "$(echo "scale=2; $t_accurate / $t_vm" | bc)x against the accurate settings"
}

# The bunny as fog at 256 voxels across (voxel 0.0387 world units), extinction 1 per world unit.
"$volmorph" voxelize "$root/scenes/meshes/bunny.obj" -o "$out/bunny.vdb" --resolution 256 -q
compare "bunny fog, 256 across" "$out/bunny.vdb" 0.0387005 1 \
    "-translate 0,5,25 -lookat 0,4.8,0 -fov 40 -res 640x360"
# The procedural cloud at 360 voxels across (voxel 0.005), extinction 30 per world unit.
"$build/tests/bench/volmorph_bench_cloud" "$out/cloud.vdb" 0.005 >/dev/null
compare "procedural cloud, 360 across" "$out/cloud.vdb" 0.005 30 \
    "-translate 0.3,0.6,2.6 -lookat 0,0.4,0 -fov 40 -res 640x360"
