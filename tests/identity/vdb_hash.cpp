// vdb_hash FILE.vdb...: one line per grid, "FILE GRID TYPE LEAVES TILES HASH", where HASH is a
// 64-bit FNV-1a over the grid's name, class, transform and background, every leaf (origin, value
// mask, every value) and every tile (level, origin, active state, value), in the tree's order.
// Two files whose lines agree hold the same grids bit for bit, whatever else their metadata says
// (file paths, versions). Used by bit_identity.sh; it is not part of volmorph.
#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

namespace {

struct Fnv {
    uint64_t h = 1469598103934665603ull;
    void bytes(const void* p, size_t n)
    {
        const auto* c = static_cast<const unsigned char*>(p);
        for (size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
    }
    template <typename T>
    void value(const T& v)
    {
        bytes(&v, sizeof v);
    }
    void text(const std::string& s)
    {
        bytes(s.data(), s.size());
        value(uint8_t(0));
    }
};

template <typename GridT>
void hashTree(const GridT& grid, Fnv& f, size_t& leaves, size_t& tiles)
{
    const auto& tree = grid.tree();
    f.value(tree.background());
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf, ++leaves) {
        f.value(leaf->origin());
        const auto& mask = leaf->getValueMask();
        for (openvdb::Index w = 0; w < mask.WORD_COUNT; ++w)
            f.value(mask.template getWord<openvdb::Index64>(w));
        f.bytes(leaf->buffer().data(), sizeof(typename GridT::ValueType) * leaf->SIZE);
    }
    auto it = tree.cbeginValueAll();
    it.setMaxDepth(GridT::TreeType::ValueAllCIter::LEAF_DEPTH - 1);
    for (; it; ++it) {
        if (it.isVoxelValue()) continue;
        ++tiles;
        f.value(it.getLevel());
        f.value(it.getCoord());
        f.value(uint8_t(it.isValueOn()));
        f.value(it.getValue());
    }
}

template <typename GridT>
bool tryHash(const openvdb::GridBase::Ptr& base, Fnv& f, size_t& leaves, size_t& tiles)
{
    const auto grid = openvdb::GridBase::grid<GridT>(base);
    if (!grid) return false;
    hashTree(*grid, f, leaves, tiles);
    return true;
}

} // namespace

int main(int argc, char** argv)
{
    openvdb::initialize();
    int status = 0;
    for (int a = 1; a < argc; ++a) {
        try {
            openvdb::io::File file(argv[a]);
            file.open(false);
            const openvdb::GridPtrVecPtr grids = file.getGrids();
            file.close();
            for (const openvdb::GridBase::Ptr& g : *grids) {
                Fnv f;
                f.text(g->getName());
                f.text(g->type());
                f.value(int(g->getGridClass()));
                const openvdb::Mat4d m = g->transform().baseMap()->getAffineMap()->getMat4();
                f.bytes(m.asPointer(), 16 * sizeof(double));
                size_t leaves = 0, tiles = 0;
                const bool known = tryHash<openvdb::FloatGrid>(g, f, leaves, tiles) ||
                                   tryHash<openvdb::Vec3SGrid>(g, f, leaves, tiles) ||
                                   tryHash<openvdb::DoubleGrid>(g, f, leaves, tiles) ||
                                   tryHash<openvdb::Int32Grid>(g, f, leaves, tiles) ||
                                   tryHash<openvdb::BoolGrid>(g, f, leaves, tiles);
                if (!known) {
                    std::fprintf(stderr, "vdb_hash: %s: grid %s has an unhandled type %s\n",
                                 argv[a], g->getName().c_str(), g->type().c_str());
                    status = 1;
                    continue;
                }
                std::printf("%s %s %s %zu %zu %016llx\n", argv[a], g->getName().c_str(),
                            g->type().c_str(), leaves, tiles, (unsigned long long)f.h);
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "vdb_hash: %s: %s\n", argv[a], e.what());
            status = 1;
        }
    }
    return status;
}
