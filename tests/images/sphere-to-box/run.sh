# The analytic scene (one box pair: a sphere moving and becoming a cube), frames 0, 2 and 4, from a
# frozen copy of the scene as it was when the references were made (the shadow map every 2 voxels).
"$VOLMORPH" render "$SOURCE/tests/images/sphere-to-box/scene.toml" --frames 0-4x2 \
    -o "$OUT/sphere-to-box.####.exr" -q
