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

# volume_scene VOLUME [TABLES]: writes $out/scene.toml, the volume VOLUME into the cube mesh
# (moved to x = 3, clear of it), with TABLES (TOML text) appended.
volume_scene() {
    printf '[source]\nvolume = "%s"\n[target]\nmesh = "%s"\ntransform = { translate = [3, 0, 0] }\n%s\n' \
        "$1" "$src/tests/data/meshes/cube.obj" "${2:-}" >"$out/scene.toml"
}
