# The analytic scene (one box pair: a sphere moving and becoming a cube), frames 0, 2 and 4.
"$VOLMORPH" render "$SOURCE/scenes/sphere-to-box.toml" --frames 0-4x2 -o "$OUT/sphere-to-box.####.exr" -q
