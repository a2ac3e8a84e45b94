#!/bin/sh
# Speed against Blender Cycles 3.4 at equal RMSE (issue 33), not a test. Each renderer is measured
# against its own converged image of the same scene: REF/volmorph.exr and REF/cycles.exr, as
# `OUT=REF cycles_compare.sh` leaves them at many samples. A render at fewer samples takes a time t
# and has a relative RMSE e (image_compare's, over pixels with alpha > 0.1); e^2 falls as 1/samples,
# so the time to reach a given RMSE is proportional to t e^2, and the speed-up at equal RMSE is
# (t e^2) of Cycles over (t e^2) of volmorph. The reference's own noise is taken out: against a
# reference of R samples, a render of n samples measures e^2 (1 + n / R). Cycles' t is its render
# alone (Blender's start and scene sync left out); volmorph's is the whole command. Also prints each
# renderer's time to reach an RMSE of 1% of the mean.
# usage: SCENE=default|cloud|fog REF=DIR [REF_CYCLES=1024] [REF_VOLMORPH=4096] [MIN_ALPHA=0.1]
#        (MIN_ALPHA=0.9 for a fog: Blender does not sample its outermost half voxel)
#        tests/bench/cycles_speed.sh [BUILD_DIR [RES [CYCLES_SAMPLES [VOLMORPH_SAMPLES [BOUNCES]]]]]
#        defaults: build 160x90 64 64 16 (RES and BOUNCES must be those of REF); REF_CYCLES and
#        REF_VOLMORPH: the references' samples
set -eu
: "${REF:?REF=DIR: the converged images (cycles_compare.sh with OUT=DIR at many samples)}"
build=${1:-build}
cycles_samples=${3:-64}
volmorph_samples=${4:-64}
compare=$build/tests/bench/volmorph_bench_image_compare
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

OUT=$out sh "$(dirname "$0")/cycles_compare.sh" "$build" "${2:-160x90}" "$cycles_samples" \
    "$volmorph_samples" "${5:-16}" >"$out/log" 2>&1 || { cat "$out/log"; exit 1; }
tv=$(sed -n 's/^volmorph (\([0-9.]*\) s.*/\1/p' "$out/log")
tc=$(sed -n 's/^cycles: rendered .* in \([0-9.]*\) s.*/\1/p' "$out/log")
ev=$("$compare" "$out/volmorph.exr" "$REF/volmorph.exr" 1 "${MIN_ALPHA:-0.1}" | sed -n 's/.* rmse \([0-9.]*\) .*/\1/p')
ec=$("$compare" "$out/cycles.exr" "$REF/cycles.exr" 1 "${MIN_ALPHA:-0.1}" | sed -n 's/.* rmse \([0-9.]*\) .*/\1/p')
awk -v tv="$tv" -v tc="$tc" -v mv="$ev" -v mc="$ec" -v sv="$volmorph_samples" \
    -v sc="$cycles_samples" -v rv="${REF_VOLMORPH:-4096}" -v rc="${REF_CYCLES:-1024}" 'BEGIN {
    ev = mv / sqrt(1 + sv / rv); ec = mc / sqrt(1 + sc / rc)
    printf "volmorph: %s samples, %.2f s, relative RMSE %.4f; to RMSE 0.01: %.1f s\n", sv, tv, ev,
        tv * ev * ev / 1e-4
    printf "cycles:   %s samples, %.2f s, relative RMSE %.4f; to RMSE 0.01: %.1f s\n", sc, tc, ec,
        tc * ec * ec / 1e-4
    printf "speed-up at equal RMSE: %.1fx\n", (tc * ec * ec) / (tv * ev * ev)
}'
