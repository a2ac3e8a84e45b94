#!/bin/sh
# lint.definitions: one definition per type name in libvolmorph/, render/ and tools/ (definitions.py),
# and the check itself: a planted second definition of a name the tree defines must fail it, the
# same type in an anonymous namespace must not.
# usage: definitions.sh SOURCE_DIR
set -u
src=$1
here=$(dirname "$0")
command -v python3 >/dev/null 2>&1 || { echo "python3 not installed: skipped"; exit 77; }
python3 "$here/definitions.py" "$src" || exit 1
plant=$(mktemp -d)
trap 'rm -rf "$plant"' EXIT
printf 'namespace volmorph::detail {\nstruct LatticeSums;\nstruct OutputLeaves {\n    int x;\n};\n}\n' >"$plant/planted.cpp"
if python3 "$here/definitions.py" "$src" "$plant/planted.cpp" >"$plant/out" 2>&1; then
    echo "lint.definitions: a planted second volmorph::detail::OutputLeaves was not found"; exit 1
fi
grep -q 'volmorph::detail::OutputLeaves: .*planted.cpp' "$plant/out" ||
    { echo "lint.definitions: the planted duplicate was not named:"; cat "$plant/out"; exit 1; }
printf 'namespace volmorph::detail {\nnamespace {\nstruct OutputLeaves {\n    int x;\n};\n}\n}\n' >"$plant/local.cpp"
python3 "$here/definitions.py" "$src" "$plant/local.cpp" >"$plant/out" 2>&1 ||
    { echo "lint.definitions: a file-local type in an anonymous namespace was refused:"; cat "$plant/out"; exit 1; }
echo "lint.definitions: a planted duplicate fails, a file-local one passes"
