# render-vdb on a voxelized sphere mesh, perspective, one coloured light, 4 samples (the step frozen at
# 0.5 voxels and the shadow map's spacing at 2, the defaults when the reference was made; RGBA
# alone, as the reference).
"$VOLMORPH" voxelize "$SOURCE/scenes/meshes/sphere.obj" -o "$OUT/sphere.vdb" --resolution 64 -q
"$VOLMORPH" render-vdb "$OUT/sphere.vdb" -o "$OUT/sphere.exr" --grid density --res 240x160 \
    --translate 0,0.6,3 --lookat 0,0,0 --fov 35 --extinction 12 --light 0.4,0.8,0.5,1,0.9,0.8 --samples 4 --step 0.5 \
    --shadow-cache 2 --no-layers
rm "$OUT/sphere.vdb"
