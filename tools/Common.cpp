#include "Common.h"

#include <sstream>

namespace volmorph::cli {
namespace {

/// The interrupter SIGINT and SIGTERM stop; set while a long operation runs.
Interrupter* gInterrupter = nullptr;

extern "C" void onStopSignal(int)
{
    if (gInterrupter) gInterrupter->requestStop();
}

} // namespace

StopSignals::StopSignals(Interrupter& interrupter)
{
    gInterrupter = &interrupter;
    struct sigaction action {};
    action.sa_handler = onStopSignal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, &mOldInt);
    sigaction(SIGTERM, &action, &mOldTerm);
}

StopSignals::~StopSignals()
{
    sigaction(SIGINT, &mOldInt, nullptr);
    sigaction(SIGTERM, &mOldTerm, nullptr);
    gInterrupter = nullptr;
}

std::string fmt(double v)
{
    std::ostringstream s;
    s.precision(4);
    s << v;
    return s.str();
}

std::string fmt(const Vec3d& v)
{
    return "[" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + "]";
}

std::string describeTopology(const MeshReport& r)
{
    std::ostringstream s;
    if (r.watertight()) s << "watertight";
    else {
        s << "open";
        if (r.boundaryEdges) s << ", " << r.boundaryEdges << " boundary edges";
        if (r.nonManifoldEdges) s << ", " << r.nonManifoldEdges << " non-manifold edges";
    }
    if (!r.consistentlyOriented()) s << ", " << r.misorientedEdges << " inconsistently oriented edges";
    s << ", " << r.components << (r.components == 1 ? " shell" : " shells");
    return s.str();
}

double secondsSince(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace volmorph::cli
