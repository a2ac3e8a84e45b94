#!/bin/sh
# Applies .clang-format to every C++ file of the project (clang-format 14, Debian's clang-format).
# --check: changes nothing, lists the files that differ and exits 1 if any does.
set -eu
cd "$(dirname "$0")/.."
command -v clang-format >/dev/null 2>&1 || { echo "clang-format not installed: skipped"; exit 77; }
[ -d .git ] || git rev-parse --git-dir >/dev/null 2>&1 || { echo "not a git checkout: skipped"; exit 77; }
files=$(git ls-files --cached --others --exclude-standard '*.cpp' '*.h') # new files too
if [ "${1:-}" = "--check" ]; then
    bad=""
    for f in $files; do clang-format "$f" | cmp -s - "$f" || bad="$bad $f"; done
    [ -z "$bad" ] || { echo "not formatted:$bad"; exit 1; }
    echo "every C++ file is formatted"
    exit 0
fi
# shellcheck disable=SC2086
clang-format -i $files
