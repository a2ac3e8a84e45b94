# The default scene's middle frame (sdf mode, three pairs, the scene's camera and lights), from a
# frozen copy of the scene as it was when the reference was made (single scattering, the shadow
# map every 2 voxels).
"$VOLMORPH" render "$SOURCE/tests/images/bunny-to-knot-frame12/scene.toml" --frames 12 \
    -o "$OUT/bunny-to-knot.####.exr" -q
