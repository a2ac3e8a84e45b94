#!/bin/sh
# Applies .clang-format to every C++ file of the project (clang-format 14, Debian's clang-format).
# --check: changes nothing, lists the files that differ and exits 1 if any does.
set -eu
cd "$(dirname "$0")/.."
files=$(git ls-files '*.cpp' '*.h')
if [ "${1:-}" = "--check" ]; then
    bad=""
    for f in $files; do clang-format "$f" | cmp -s - "$f" || bad="$bad $f"; done
    [ -z "$bad" ] || { echo "not formatted:$bad"; exit 1; }
    echo "every C++ file is formatted"
    exit 0
fi
# shellcheck disable=SC2086
clang-format -i $files
