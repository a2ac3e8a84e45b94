# Shared by the surface-morph benchmarks (surface_bench.sh, star_bench.sh), sourced, not run: a
# scene of source.obj and target.obj at 256 voxels across over 24 frames, and the medians of RUNS
# timed morphs. Needs $vm (the volmorph binary), $work (a scratch folder holding the meshes) and
# $runs.

scene() { # MODE [SURFACE TABLE]
    printf '[source]\nmesh = "source.obj"\n[target]\nmesh = "target.obj"\n[volume]\nresolution = 256\n'
    printf '[blend]\nmode = "%s"\n%s\n[frames]\nrange = "1-24"\noutput = "out/f.####.exr"\n' "$1" "${2:-}"
}
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
measure() { # SCENE OUTPUT: "seconds peak-MB", medians
    times="" peaks=""
    i=0
    while [ "$i" -lt "$runs" ]; do
        rm -rf "$work/o" "$work/cache"
        VOLMORPH_CACHE="$work/cache" /usr/bin/time -f "%e %M" -o "$work/t" "$vm" morph "$1" -o "$work/o/$2" -q
        times="$times $(cut -d' ' -f1 "$work/t")" peaks="$peaks $(cut -d' ' -f2 "$work/t")"
        i=$((i + 1))
    done
    echo "$(echo "$times" | median) $(echo "$(echo "$peaks" | median) / 1024" | bc)"
}
