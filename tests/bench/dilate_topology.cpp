// Writes a copy of a .vdb whose float grids have their active topology dilated by one voxel (26
// neighbours, tiles expanded into voxels), values unchanged. Rendered, it is the same density
// field; it only lets vdb_render's undilated ray intersector reach the trilinear tail within one
// voxel outside the active voxels, so that a vdb_render reference is not missing it.
// usage: volmorph_bench_dilate IN.vdb OUT.vdb
#include <openvdb/openvdb.h>
#include <openvdb/tools/Morphology.h>

#include <cstdio>

int main(int argc, char** argv)
{
    if (argc != 3) {
        std::fprintf(stderr, "usage: %s IN.vdb OUT.vdb\n", argv[0]);
        return 2;
    }
    openvdb::initialize();
    openvdb::io::File in(argv[1]);
    in.open();
    openvdb::GridPtrVecPtr grids = in.getGrids();
    in.close();
    for (const openvdb::GridBase::Ptr& g : *grids)
        if (auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(g)) {
            f->tree().voxelizeActiveTiles();
            openvdb::tools::dilateActiveValues(f->tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                               openvdb::tools::EXPAND_TILES);
        }
    openvdb::io::File(argv[2]).write(*grids);
    return 0;
}
