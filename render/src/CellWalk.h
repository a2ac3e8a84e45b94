// The walk of a ray through the interpolation cells of a density grid.
#pragma once

#include "Cell.h"
#include "GridReaders.h"

#include <openvdb/tools/Interpolation.h>

#include <cmath>
#include <limits>

namespace volmorph::render {

/// Amanatides and Woo's 3D DDA over interpolation cells: the cell the ray is in, and the ray times
/// at which it crosses the next cell wall along each axis.
struct CellDda {
    int cell[3], step[3];
    double next[3], delta[3];

    /// Starts at ray time t (voxels).
    __attribute__((always_inline)) void start(const Medium1D& ray, double t)
    {
        const Vec3d start = ray.eye + ray.dir * t;
        for (int a = 0; a < 3; ++a) {
            cell[a] = int(std::floor(start[a]));
            const double d = ray.dir[a];
            if (d > 0.0) {
                step[a] = 1;
                delta[a] = 1.0 / d;
                next[a] = t + (cell[a] + 1 - start[a]) * delta[a];
            } else if (d < 0.0) {
                step[a] = -1;
                delta[a] = -1.0 / d;
                next[a] = t + (start[a] - cell[a]) * delta[a];
            } else {
                step[a] = 0;
                delta[a] = std::numeric_limits<double>::infinity();
                next[a] = std::numeric_limits<double>::infinity();
            }
        }
    }

    /// The axis whose wall the ray crosses first.
    __attribute__((always_inline)) int axis() const
    {
        return next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
    }

    __attribute__((always_inline)) void advance(int a)
    {
        cell[a] += step[a];
        next[a] += delta[a];
    }
};

/// The ray time (voxels) at which the ray leaves the constant region [b, b + 7]^3 of the 8^3 block
/// holding `cell`, at most tb.
__attribute__((always_inline)) inline double blockExit(const Medium1D& ray, const int (&cell)[3],
                                                       double tb)
{
    double exit = tb;
    for (int k = 0; k < 3; ++k) {
        const double d = ray.dir[k];
        if (d == 0.0) continue;
        const double lo = double(cell[k] & ~7), wall = d > 0.0 ? lo + 7.0 : lo;
        exit = std::min(exit, (wall - ray.eye[k]) / d);
    }
    return exit;
}

/// Walks the interpolation cells that the index ray eye + t dir crosses for t in [ta, tb]
/// (Amanatides and Woo's 3D DDA), calling visit(cell, t0, t1) for each piece whose cell has a
/// non-zero density somewhere; stops early when visit returns false. Returns false if stopped.
/// Where the ray enters an 8^3 block of one value (a tile, the background, a constant leaf), every
/// cell within the block's [b, b + 7]^3 is constant: the whole crossing is one piece. Consecutive
/// pieces of one constant density (such blocks, cells of one value, level-set cells wholly inside)
/// are visited as one piece marked Cell::block.
template <typename Visit>
bool walkCells(DensityReader& reader, const Medium1D& ray, double ta, double tb, Visit&& visit)
{
    CellDda dda;
    Cell c, run;
    bool pending = false; // a run of constant pieces not yet visited: [runStart, pendingEnd]
    double runStart = 0.0, pendingEnd = 0.0;
    float pendingRho = 0.0f;
    double t = ta;
    while (t < tb) {
        dda.start(ray, t);
        bool restart = false;
        while (t < tb && !restart) {
            const int a = dda.axis();
            double t1 = std::min(dda.next[a], tb);
            c.origin = Coord(dda.cell[0], dda.cell[1], dda.cell[2]);
            c.block = false;
            if (!reader.cell(c.origin, c.v)) {
                const float value = reader.tile;
                for (int i = 0; i < 8; ++i) (&c.v[0][0][0])[i] = value;
                const double exit = blockExit(ray, dda.cell, tb);
                if (exit > t1 + 1e-6) { // the rest of the block in one piece, then a new start
                    t1 = exit;
                    c.block = true;
                    restart = true;
                }
            }
            if (t1 > t) {
                openvdb::tools::BoxSampler::extrema(c.v, c.lo, c.hi);
                const bool empty = ray.levelSet ? c.lo >= 0.0f : c.hi <= 0.0f;
                // Constant density along the piece: a fog cell of one value, a level-set cell
                // wholly inside.
                const bool constant = c.block || (ray.levelSet ? c.hi < 0.0f : c.lo == c.hi);
                const float rho = ray.levelSet ? 1.0f : c.hi;
                if (pending && !(constant && !empty && rho == pendingRho && t == pendingEnd)) {
                    pending = false;
                    if (!visit(run, runStart, pendingEnd)) return false;
                }
                if (constant && !empty) {
                    // Runs of constant pieces of one density are visited as one piece.
                    if (!pending) {
                        pending = true;
                        run = c;
                        run.block = true;
                        runStart = t;
                        pendingRho = rho;
                    }
                    pendingEnd = t1;
                } else if (!empty && !visit(c, t, t1)) {
                    return false;
                }
            }
            t = t1;
            if (!restart) dda.advance(a);
        }
    }
    return !pending || visit(run, runStart, pendingEnd);
}

} // namespace volmorph::render
