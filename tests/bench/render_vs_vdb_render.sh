#!/bin/sh
# volmorph render-vdb against OpenVDB's vdb_render on the same grid, camera and light, with shadows,
# in one run: median wall time of RUNS renders each (whole commands: start-up, reading, rendering,
# writing), and each one's alpha error against two references made by vdb_render at a tiny step
# (0.05 voxel):
#   literal:   the grid as is, -cutoff 1e-7 (what the issue names). vdb_render stops a ray when the
#              squared length of its RGB transmittance is below the cutoff, i.e. T < 1.8e-4, and its
#              undilated ray intersector skips the trilinear tail within one voxel outside the
#              active voxels; so this reference shares vdb_render's own truncations.
#   converged: the same density with its active topology dilated by one voxel (values unchanged,
#              volmorph_bench_dilate) and -cutoff 1e-14 (T < 6e-8): nothing skipped or truncated.
# Alpha does not depend on shadows, so the references use a coarse shadow step. EXRs are float on
# both sides (vdb_render writes float), so half quantization is not counted as error.
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

# The bunny as fog at 256 voxels across (voxel 0.0387 world units); extinction 1 per world unit,
# albedo 0.8: vdb_render's coefficients are per voxel.
"$volmorph" voxelize "$root/scenes/meshes/bunny.obj" -o "$out/bunny.vdb" --resolution 256 -q
"$dilate" "$out/bunny.vdb" "$out/dilated.vdb"
absorb=0.0077401   # 1 * 0.2 * 0.0387005
scatter=0.0309604  # 1 * 0.8 * 0.0387005
camera="-translate 0,5,25 -lookat 0,4.8,0 -fov 40 -res 640x360"
vdb_args="$camera -absorb $absorb,$absorb,$absorb -scatter $scatter,$scatter,$scatter -light 0.3,0.7,0.6,1,1,1 -name density"
vm="$volmorph render-vdb $out/bunny.vdb --translate 0,5,25 --lookat 0,4.8,0 --fov 40 --res 640x360
    --extinction 1 --albedo 0.8 --light 0.3,0.7,0.6 --samples 1 --step 0.5 --grid density --float"

vdb_render "$out/bunny.vdb" "$out/ref_literal.exr" $vdb_args -cutoff 1e-7 -step 0.05 -shadowstep 20 >/dev/null
vdb_render "$out/dilated.vdb" "$out/ref_converged.exr" $vdb_args -cutoff 1e-14 -step 0.05 -shadowstep 20 >/dev/null

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

t_vdb=$(time_runs vdb_render "$out/bunny.vdb" "$out/vdb.exr" $vdb_args -cutoff 1e-7 -step 1 -shadowstep 3)
t_vm=$(time_runs $vm -o "$out/vm.exr")
for who in vdb vm; do
    name=$([ $who = vdb ] && echo "vdb_render (step 1, shadow step 3, -cutoff 1e-7)" || echo "volmorph render-vdb (defaults)")
    t=$([ $who = vdb ] && echo "$t_vdb" || echo "$t_vm")
    echo "$name: median $t s"
    echo "    alpha vs literal reference:   $(alpha_error "$out/$who.exr" "$out/ref_literal.exr")"
    echo "    alpha vs converged reference: $(alpha_error "$out/$who.exr" "$out/ref_converged.exr")"
done
echo "speed-up: $(echo "scale=2; $t_vdb / $t_vm" | bc)x"
