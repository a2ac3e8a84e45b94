#!/bin/sh
# The size rules of ARCHITECTURE.md for libvolmorph/, render/ and tools/: no unit (file) over 500 lines, no
# function over 80 lines as clang-tidy's readability-function-size counts them (LineThreshold 80,
# headers included; a function may be exempted by a NOLINTNEXTLINE(readability-function-size)
# comment that gives its reason). Exits 77 (skipped) when clang-tidy or the build's compile_commands.json is
# missing.
# usage: sizes.sh SOURCE_DIR BUILD_DIR
set -u
src=$1
build=$2
command -v clang-tidy >/dev/null 2>&1 || { echo "clang-tidy not installed: skipped"; exit 77; }
[ -f "$build/compile_commands.json" ] || { echo "no $build/compile_commands.json: skipped"; exit 77; }
cd "$src"
status=0
long=$(find libvolmorph render tools -name '*.cpp' -o -name '*.h' | xargs wc -l | awk '$2 != "total" && $1 > 500')
if [ -n "$long" ]; then echo "units over 500 lines:"; echo "$long"; status=1; fi
units=$(find libvolmorph render tools -name '*.cpp' | sort)
jobs=$(nproc 2>/dev/null || echo 2)
all=$(echo "$units" | xargs -P "$jobs" -n 2 clang-tidy -p "$build" --quiet --header-filter='.*/(libvolmorph|render|tools)/.*' \
    --checks='-*,readability-function-size' \
    --config='{CheckOptions: [{key: readability-function-size.LineThreshold, value: 80}]}' 2>&1)
# A unit clang-tidy cannot parse would go unmeasured: that is a failure, not a pass.
errors=$(echo "$all" | grep -E 'error:' || true)
if [ -n "$errors" ]; then echo "clang-tidy could not read every unit:"; echo "$errors"; status=1; fi
report=$(echo "$all" | grep -E 'warning: function|lines including' | sort -u || true)
if [ -n "$report" ]; then echo "functions over 80 lines:"; echo "$report"; status=1; fi
[ "$status" -eq 0 ] && echo "libvolmorph/, render/ and tools/: every unit <= 500 lines, every function <= 80 lines ($(echo "$units" | wc -l) units)"
exit "$status"
