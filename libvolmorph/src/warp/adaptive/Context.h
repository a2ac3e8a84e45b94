// One thread's scratch for the approximated warp: the leaf being filled, what the error bound
// found of the last cube analysed, and the counters summed into the stats.
#pragma once

#include "warp/AdaptiveWarp.h"
#include "warp/adaptive/ErrorBound.h"
#include "warp/adaptive/LatticeSums.h"
#include "warp/adaptive/LeafKernel.h"

#include <memory>
#include <vector>

namespace volmorph::detail {

struct WarpContext {
    const Occupancy* source = nullptr;
    const Occupancy* target = nullptr;
    const AdaptiveWarp::LeafFunction* fn = nullptr;
    WarpLeaf leaf;
    double maxError = 0.0;
    uint64_t evaluations = 0, near = 0, allFar = 0, leaves = 0;
    // Per pair, per leaf (scratch).
    std::unique_ptr<LeafJob> job = std::make_unique<LeafJob>();
    PairBounds bounds;
    std::vector<char> isNear;
    std::vector<size_t> nearList;            ///< the near pairs, by type, then by index
    std::vector<float> shareList, curveList; ///< selectNear's copies of the bound's columns
    // What analyze() found of the last cube.
    const LatticePoint* corner[8];
    bool cornersOk = false, tiny = false, coreTouches = false;
    size_t dominant = 0;
    double wMinSum = 0.0, rhoMax = 0.0, boundAllFar = 0.0;
    double wCornerMin = 0.0; ///< the smallest W at the corners (where cornersOk, else 0)
    Vec3d rhoLo[2], rhoHi[2], rhoMid[2]; ///< the box of the corners' rho_k, source and target side
    double cornerB[2][3][8]; ///< B at the corners: [side][axis][corner] (where cornersOk)
};

} // namespace volmorph::detail
