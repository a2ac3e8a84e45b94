# Sourced by CLI tests called as `test.sh VOLMORPH SOURCE_DIR`: sets volmorph and src, makes a
# scratch folder $out removed on exit, and defines expect_files.
volmorph=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# expect_files DIR "a b c": DIR holds exactly these files (ls order), or the test fails saying
# what it holds.
expect_files() {
    held=$(ls "$1" | tr '\n' ' ')
    [ "$held" = "$2 " ] || { echo "$1 holds: $held(expected $2)"; exit 1; }
}
