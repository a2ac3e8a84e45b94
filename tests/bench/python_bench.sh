#!/bin/sh
# The Python module against the command line on the same work, whole processes, alternating:
# `volmorph morph SCENE --frames F` against `python3 -c 'volmorph.Scene(SCENE).morph(F)'`, and the
# same for render. Medians of RUNS runs (default 5), with each side's peak resident size.
# usage: [RUNS=5] sh tests/bench/python_bench.sh BUILD_DIR SCENE FRAME
set -eu
build=$1 scene=$2 frame=$3 runs=${RUNS:-5}
exe=$build/bin/volmorph
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export PYTHONPATH=$build/python
measure() { # name command...: appends "seconds kilobytes" to $tmp/name
    name=$1; shift
    /usr/bin/time -f "%e %M" -o "$tmp/one" "$@" >/dev/null 2>&1
    cat "$tmp/one" >>"$tmp/$name"
}
"$exe" morph "$scene" --frames "$frame" -o "$tmp/warm.####.vdb" -q # the voxel cache, once
i=0
while [ "$i" -lt "$runs" ]; do
    measure cli_morph "$exe" morph "$scene" --frames "$frame" -o "$tmp/m.####.vdb" -q
    measure py_morph /usr/bin/python3 -c "import volmorph; volmorph.Scene('$scene').morph($frame)"
    measure cli_render "$exe" render "$scene" --frames "$frame" -o "$tmp/r.####.exr" -q
    measure py_render /usr/bin/python3 -c "import volmorph; volmorph.Scene('$scene').render($frame)"
    i=$((i + 1))
done
median() { sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
for work in morph render; do
    c=$(cut -d' ' -f1 "$tmp/cli_$work" | median) p=$(cut -d' ' -f1 "$tmp/py_$work" | median)
    cm=$(cut -d' ' -f2 "$tmp/cli_$work" | median) pm=$(cut -d' ' -f2 "$tmp/py_$work" | median)
    awk -v w="$work" -v c="$c" -v p="$p" -v cm="$cm" -v pm="$pm" 'BEGIN {
        printf "%-6s  command %.2f s %4.0f MB   python %.2f s %4.0f MB   ratio %.2f\n",
               w, c, cm / 1024, p, pm / 1024, p / c }'
done
