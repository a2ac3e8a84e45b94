#include <volmorph/core/VdbRead.h>

#include <openvdb/io/Stream.h>

#include <fstream>
#include <mutex>
#include <stdexcept>

namespace volmorph {

openvdb::GridPtrVecPtr readVdbGrids(const std::filesystem::path& path)
{
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot open the file");
    try {
        in.exceptions(std::ios::failbit | std::ios::badbit);
        // Not delayed: a delayed Stream copies the input to a temporary file and reads that
        // unchecked.
        openvdb::io::Stream stream(in, /*delayLoad=*/false);
        return stream.getGrids();
    } catch (const std::ios_base::failure&) {
        throw std::runtime_error("it ends early: truncated or damaged");
    } catch (const std::exception& e) {
        throw std::runtime_error(e.what());
    }
}

} // namespace volmorph
