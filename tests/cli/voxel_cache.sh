#!/bin/sh
# The voxel cache: a second run reads the voxels instead of voxelizing and renders the same pixels;
# a truncated or garbage entry, or one without its checksum, is reported, rebuilt and replaced,
# never trusted; changing an input misses; an unusable cache folder only warns.
# usage: voxel_cache.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
scene=$2/scenes/sphere-to-box.toml
dir=$(mktemp -d)
trap 'chmod -R u+w "$dir"; rm -rf "$dir"' EXIT
cache=$dir/cache

same() { # frames of two folders are equal pixel for pixel
    for f in 0001 0003; do
        "$volmorph" diff -q --fail 0 "$1/f.$f.exr" "$2/f.$f.exr" || { echo "frame $f differs: $1 vs $2"; exit 1; }
    done
}
run() { # folder, extra flags...
    out=$1; shift
    "$volmorph" render "$scene" --frames 1,3 -o "$dir/$out/f.####.exr" --cache "$cache" "$@" >"$dir/log" 2>"$dir/err"
}

"$volmorph" render "$scene" --frames 1,3 -o "$dir/nocache/f.####.exr" --no-cache >/dev/null
run first
grep -q "cached in $cache/" "$dir/log" || { echo "first run did not store:"; cat "$dir/log"; exit 1; }
entry=$(ls "$cache"/*.vdb)
[ "$(ls "$cache"/*.vdb | wc -l)" = 1 ] && [ -f "${entry%.vdb}.sha1" ] || { echo "cache holds: $(ls "$cache")"; exit 1; }
run hit
grep -q "read from the cache" "$dir/log" || { echo "second run missed:"; cat "$dir/log"; exit 1; }
same "$dir/nocache" "$dir/hit"

for damage in truncate garbage nochecksum; do
    case $damage in
        truncate) head -c 5000 "$entry" >"$dir/t"; mv "$dir/t" "$entry" ;;
        garbage) head -c 5000 /dev/urandom >"$dir/t"; mv "$dir/t" "$entry" ;;
        nochecksum) rm "${entry%.vdb}.sha1" ;;
    esac
    run $damage
    grep -q "voxel cache entry not used" "$dir/err" || { echo "$damage entry not reported:"; cat "$dir/err"; exit 1; }
    same "$dir/nocache" "$dir/$damage"
    run after-$damage
    grep -q "read from the cache" "$dir/log" || { echo "entry not replaced after $damage"; cat "$dir/log"; exit 1; }
done

# Another transform is another key.
sed "s|meshes/|$2/scenes/meshes/|; s|scale = 0.8 }|scale = 0.7 }|" "$scene" >"$dir/changed.toml"
"$volmorph" render "$dir/changed.toml" --frames 1 -o "$dir/changed/f.####.exr" --cache "$cache" >"$dir/log"
grep -q "cached in" "$dir/log" || { echo "changed scene hit the old entry"; cat "$dir/log"; exit 1; }
[ "$(ls "$cache"/*.vdb | wc -l)" = 2 ] || { echo "cache holds: $(ls "$cache")"; exit 1; }

# A cache folder that cannot be created (its parent is a file): a warning, the frames still appear.
touch "$dir/plainfile"
"$volmorph" render "$scene" --frames 1 -o "$dir/nowhere/f.####.exr" --cache "$dir/plainfile/c" >/dev/null 2>"$dir/err"
grep -q "were not cached" "$dir/err" || { echo "no warning for an unusable cache folder:"; cat "$dir/err"; exit 1; }
[ -f "$dir/nowhere/f.0001.exr" ] || { echo "no frame with an unusable cache folder"; exit 1; }
echo "voxel cache: hit equals no-cache pixel for pixel; damaged entries rebuilt; changed inputs miss"
