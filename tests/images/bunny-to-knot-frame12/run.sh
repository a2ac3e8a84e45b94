# The default scene's middle frame (sdf mode, three pairs, the scene's camera and lights).
"$VOLMORPH" render "$SOURCE/scenes/bunny-to-knot.toml" --frames 12 -o "$OUT/bunny-to-knot.####.exr" -q
