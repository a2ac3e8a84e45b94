#!/bin/sh
# The size rules of ARCHITECTURE.md for libvolmorph/, render/ and tools/: no unit (file) over 500 lines, no
# function over 80 lines as clang-tidy's readability-function-size counts them (LineThreshold 80,
# headers included; a function may be exempted by a NOLINTNEXTLINE(readability-function-size)
# comment that gives its reason). Exits 77 (skipped) when clang-tidy or the build's compile_commands.json is
# missing.
#
# clang-tidy parses every unit with OpenVDB's headers: 450 s of CPU. Each unit's report is kept in
# ${XDG_CACHE_HOME:-~/.cache}/volmorph/lint-sizes under a hash of what decides it (clang-tidy's version,
# this script, the unit, and every header and CMake file of the project), so a tree measured once (a
# fresh clone elsewhere too) is not parsed again; a unit clang-tidy could not read is never kept.
# usage: sizes.sh SOURCE_DIR BUILD_DIR
set -u
src=$1
build=$2
self=$(cat "$0")
command -v clang-tidy >/dev/null 2>&1 || { echo "clang-tidy not installed: skipped"; exit 77; }
[ -f "$build/compile_commands.json" ] || { echo "no $build/compile_commands.json: skipped"; exit 77; }
cd "$src"
status=0
long=$(find libvolmorph render tools -name '*.cpp' -o -name '*.h' | xargs wc -l | awk '$2 != "total" && $1 > 500')
if [ -n "$long" ]; then echo "units over 500 lines:"; echo "$long"; status=1; fi
units=$(find libvolmorph render tools -name '*.cpp' | sort)
jobs=$(nproc 2>/dev/null || echo 2)
cache=${XDG_CACHE_HOME:-$HOME/.cache}/volmorph/lint-sizes
mkdir -p "$cache" 2>/dev/null || cache=$(mktemp -d)
shared=$({ clang-tidy --version; echo "$self"; cat CMakeLists.txt;
           find libvolmorph render tools cmake -name '*.h' -o -name '*.cmake' -o -name CMakeLists.txt | sort | xargs cat; } |
         sha256sum | cut -c1-64)
todo=""
for unit in $units; do
    key=$({ echo "$shared $unit"; cat "$unit"; } | sha256sum | cut -c1-64)
    [ -f "$cache/$key" ] || todo="$todo$key $unit
"
done
# One clang-tidy per unit; its report is kept unless it could not read the unit.
printf '%s' "$todo" | xargs -r -P "$jobs" -L 1 sh -c '
    out=$(clang-tidy -p "$0" --quiet --header-filter=".*/(libvolmorph|render|tools)/.*" \
        --checks="-*,readability-function-size" \
        --config="{CheckOptions: [{key: readability-function-size.LineThreshold, value: 80}]}" "$3" 2>&1 |
        sed "s|$PWD/||g")
    if echo "$out" | grep -q "error:"; then echo "$out"; exit 0; fi
    printf "%s\n" "$out" >"$1/$2.tmp" && mv "$1/$2.tmp" "$1/$2"' "$build" "$cache" >"$cache/.errors.$$" 2>&1
all=$(cat "$cache/.errors.$$"; rm -f "$cache/.errors.$$"
      for unit in $units; do cat "$cache/$({ echo "$shared $unit"; cat "$unit"; } | sha256sum | cut -c1-64)" 2>/dev/null || echo "error: $unit was not measured"; done)
# A unit clang-tidy cannot parse would go unmeasured: that is a failure, not a pass.
errors=$(echo "$all" | grep -E 'error:' || true)
if [ -n "$errors" ]; then echo "clang-tidy could not read every unit:"; echo "$errors"; status=1; fi
report=$(echo "$all" | grep -E 'warning: function|lines including' | sort -u || true)
if [ -n "$report" ]; then echo "functions over 80 lines:"; echo "$report"; status=1; fi
[ "$status" -eq 0 ] && echo "libvolmorph/, render/ and tools/: every unit <= 500 lines, every function <= 80 lines ($(echo "$units" | wc -l) units)"
exit "$status"
