#include "warp/VelocityLeaf.h"

#include <algorithm>

namespace volmorph::detail {

/// Both sides' velocities on the leaf's lattice, 4 voxels apart: point (i, j, k) at origin + 4 (i,
/// j, k).
struct Lattice {
    Vec3d v[2][3][3][3]; ///< side (0 source, 1 target), i, j, k

    /// The trilinear interpolant of side s at voxel offset (x, y, z), each in 0..8.
    Vec3d at(int s, int x, int y, int z) const
    {
        const int i = std::min(x / 4, 1), j = std::min(y / 4, 1), k = std::min(z / 4, 1);
        const double fx = (x - 4 * i) / 4.0, fy = (y - 4 * j) / 4.0, fz = (z - 4 * k) / 4.0;
        Vec3d out(0.0);
        for (int c = 0; c < 8; ++c) {
            const int a = c >> 2, b = (c >> 1) & 1, d = c & 1;
            const double w = (a ? fx : 1.0 - fx) * (b ? fy : 1.0 - fy) * (d ? fz : 1.0 - fz);
            out += w * v[s][i + a][j + b][k + d];
        }
        return out;
    }

    /// The lattice points between the corners (i, j, k in {0, 2}), from the corners alone: the
    /// leaf-wide trilinear interpolant written on the finer lattice.
    void fillFromCorners()
    {
        for (int s = 0; s < 2; ++s)
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    for (int k = 0; k < 3; ++k)
                        if (i == 1 || j == 1 || k == 1) v[s][i][j][k] = coarse(s, i, j, k);
    }

    /// Every voxel's interpolant of side s, separably: along x, then y, then z (single precision,
    /// as stored).
    void interpolateAll(int s, Vec3f out[512]) const
    {
        Vec3f alongX[8][3][3], alongXY[8][8][3];
        for (int x = 0; x < 8; ++x) {
            const int i = x / 4;
            const float f = float(x - 4 * i) / 4.0f;
            for (int j = 0; j < 3; ++j)
                for (int k = 0; k < 3; ++k)
                    alongX[x][j][k] =
                        Vec3f(v[s][i][j][k]) * (1.0f - f) + Vec3f(v[s][i + 1][j][k]) * f;
        }
        for (int x = 0; x < 8; ++x)
            for (int y = 0; y < 8; ++y) {
                const int j = y / 4;
                const float f = float(y - 4 * j) / 4.0f;
                for (int k = 0; k < 3; ++k)
                    alongXY[x][y][k] = alongX[x][j][k] * (1.0f - f) + alongX[x][j + 1][k] * f;
            }
        for (int x = 0; x < 8; ++x)
            for (int y = 0; y < 8; ++y)
                for (int z = 0; z < 8; ++z) {
                    const int k = z / 4;
                    const float f = float(z - 4 * k) / 4.0f;
                    out[(x * 8 + y) * 8 + z] =
                        alongXY[x][y][k] * (1.0f - f) + alongXY[x][y][k + 1] * f;
                }
    }

private:
    Vec3d coarse(int s, int i, int j, int k) const
    {
        Vec3d out(0.0);
        for (int c = 0; c < 8; ++c) {
            const int a = (c >> 2) * 2, b = ((c >> 1) & 1) * 2, d = (c & 1) * 2;
            const double w = (a ? i : 2 - i) * (b ? j : 2 - j) * (d ? k : 2 - k) / 8.0;
            out += w * v[s][a][b][d];
        }
        return out;
    }
};

namespace {

Vec3d at(const openvdb::Coord& origin, int x, int y, int z)
{
    return Vec3d(origin.x() + x, origin.y() + y, origin.z() + z);
}

/// The check point of sub-cube c (bit 2: +x, bit 1: +y, bit 0: +z): its centre.
openvdb::Coord checkPoint(int c)
{
    return openvdb::Coord((c >> 2) ? 6 : 2, ((c >> 1) & 1) ? 6 : 2, (c & 1) ? 6 : 2);
}

} // namespace

bool VelocityLeaf::exact(const Vec3d& p, Vec3d& source, Vec3d& target) const
{
    InverseWarp::Derivatives ds, dt;
    mKernel.derivatives(p, ds, dt);
    const bool s = InverseWarp::velocity(ds, source);
    const bool t = InverseWarp::velocity(dt, target);
    return s && t;
}

void VelocityLeaf::fillExact(const openvdb::Coord& origin, const openvdb::util::NodeMask<3>& on,
                             Vec3f source[512], Vec3f target[512]) const
{
    for (auto it = on.beginOn(); it; ++it) {
        const openvdb::Index n = it.pos();
        Vec3d s, t;
        exact(at(origin, int(n >> 6), int((n >> 3) & 7), int(n & 7)), s, t);
        source[n] = Vec3f(s);
        target[n] = Vec3f(t);
    }
}

void VelocityLeaf::refine(const openvdb::Coord& origin, int c, double speed, const Lattice& coarse,
                          const openvdb::util::NodeMask<3>& on, Vec3f source[512],
                          Vec3f target[512]) const
{
    const int ox = (c >> 2) * 4, oy = ((c >> 1) & 1) * 4, oz = (c & 1) * 4;
    Vec3d fine[2][3][3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) {
                if (i != 1 && j != 1 && k != 1) { // a point of the coarse lattice
                    for (int s = 0; s < 2; ++s)
                        fine[s][i][j][k] =
                            coarse.v[s][ox / 4 + i / 2][oy / 4 + j / 2][oz / 4 + k / 2];
                } else if (!exact(at(origin, ox + 2 * i, oy + 2 * j, oz + 2 * k), fine[0][i][j][k],
                                  fine[1][i][j][k])) {
                    return fillExact(origin, on, source, target); // a fold
                }
            }
    // The trilinear interpolant of side s in fine cell `cell` at fractions f.
    auto interpolate = [&fine](int s, const int cell[3], const double f[3]) {
        Vec3d v(0.0);
        for (int corner = 0; corner < 8; ++corner) {
            const int a = corner >> 2, b = (corner >> 1) & 1, d = corner & 1;
            const double w =
                (a ? f[0] : 1.0 - f[0]) * (b ? f[1] : 1.0 - f[1]) * (d ? f[2] : 1.0 - f[2]);
            v += w * fine[s][cell[0] + a][cell[1] + b][cell[2] + d];
        }
        return v;
    };
    // Each fine cell is checked at its centre voxel, as the sub-cubes were.
    bool passed[8];
    for (int q = 0; q < 8; ++q) {
        const int cell[3] = {q >> 2, (q >> 1) & 1, q & 1};
        const double half[3] = {0.5, 0.5, 0.5};
        Vec3d e[2];
        passed[q] =
            exact(at(origin, ox + 2 * cell[0] + 1, oy + 2 * cell[1] + 1, oz + 2 * cell[2] + 1),
                  e[0], e[1]);
        for (int s = 0; s < 2 && passed[q]; ++s)
            passed[q] = (interpolate(s, cell, half) - e[s]).length() <= mTolerance * speed;
    }
    openvdb::util::NodeMask<3> rest;
    for (auto it = on.beginOn(); it; ++it) {
        const openvdb::Index n = it.pos();
        const int u[3] = {int(n >> 6) - ox, int((n >> 3) & 7) - oy, int(n & 7) - oz};
        int cell[3];
        double f[3];
        for (int a = 0; a < 3; ++a) {
            cell[a] = std::min(u[a] / 2, 1);
            f[a] = (u[a] - 2 * cell[a]) / 2.0;
        }
        if (!passed[cell[0] * 4 + cell[1] * 2 + cell[2]]) {
            rest.setOn(n);
            continue;
        }
        source[n] = Vec3f(interpolate(0, cell, f));
        target[n] = Vec3f(interpolate(1, cell, f));
    }
    fillExact(origin, rest, source, target);
}

void VelocityLeaf::finishFailed(const openvdb::Coord& origin, const openvdb::util::NodeMask<3>& on,
                                const bool passed[8], const double miss[8], double speed,
                                const Lattice& lattice, Vec3f source[512], Vec3f target[512]) const
{
    openvdb::util::NodeMask<3> rest[8];
    for (auto it = on.beginOn(); it; ++it) {
        const openvdb::Index n = it.pos();
        const int c = int((n >> 8) * 4 + ((n >> 5) & 1) * 2 + ((n >> 2) & 1));
        if (!passed[c]) rest[c].setOn(n);
    }
    // A finer lattice costs 19 points and 8 checks: worth it where the sub-cube has more active
    // voxels and its check missed by little (halving the spacing quarters a smooth field's error).
    constexpr openvdb::Index kFinePoints = 19 + 8;
    constexpr double kRefinable = 8.0;
    for (int c = 0; c < 8; ++c) {
        if (passed[c] || rest[c].isOff()) continue;
        if (miss[c] <= kRefinable && rest[c].countOn() > kFinePoints)
            refine(origin, c, speed, lattice, rest[c], source, target);
        else
            fillExact(origin, rest[c], source, target);
    }
}

int VelocityLeaf::fill(const openvdb::Coord& origin, const openvdb::util::NodeMask<3>& on,
                       Vec3f source[512], Vec3f target[512]) const
{
    // Coarse: the leaf's 8 corners and the 8 checks; fine: the other 19 lattice points.
    constexpr openvdb::Index kEvaluations = 8 + 8 + 19;
    if (on.countOn() <= kEvaluations) {
        fillExact(origin, on, source, target);
        return 0;
    }
    Lattice lattice;
    double speed = 0.0;
    auto evaluate = [&](int i, int j, int k) {
        Vec3d& s = lattice.v[0][i][j][k];
        Vec3d& t = lattice.v[1][i][j][k];
        const bool ok = exact(at(origin, 4 * i, 4 * j, 4 * k), s, t);
        speed = std::max({speed, s.length(), t.length()});
        return ok;
    };
    bool regular = true;
    for (int c = 0; c < 8; ++c) regular &= evaluate((c >> 2) * 2, ((c >> 1) & 1) * 2, (c & 1) * 2);
    Vec3d checks[2][8];
    for (int c = 0; c < 8; ++c) {
        const openvdb::Coord p = checkPoint(c);
        regular &= exact(at(origin, p.x(), p.y(), p.z()), checks[0][c], checks[1][c]);
    }
    if (!regular) { // a fold of the warp: no interpolation across it
        fillExact(origin, on, source, target);
        return 0;
    }
    // Each sub-cube passes when the interpolant at its centre is within the tolerance of both
    // sides' exact velocities there (relative to the largest speed met on the lattice).
    bool passed[8];
    double miss[8]; // the check's error, relative to the tolerance
    auto check = [&] {
        int passing = 0;
        for (int c = 0; c < 8; ++c) {
            const openvdb::Coord p = checkPoint(c);
            miss[c] = 0.0;
            for (int s = 0; s < 2; ++s)
                miss[c] =
                    std::max(miss[c], (lattice.at(s, p.x(), p.y(), p.z()) - checks[s][c]).length() /
                                          (mTolerance * speed));
            passed[c] = miss[c] <= 1.0;
            passing += passed[c];
        }
        return passing;
    };
    lattice.fillFromCorners();
    int passing = check();
    if (passing < 8) {
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                for (int k = 0; k < 3; ++k)
                    if ((i == 1 || j == 1 || k == 1) && !evaluate(i, j, k)) {
                        fillExact(origin, on, source, target);
                        return 0;
                    }
        passing = check();
    }
    if (passing > 0) {
        lattice.interpolateAll(0, source);
        lattice.interpolateAll(1, target);
    }
    if (passing < 8) finishFailed(origin, on, passed, miss, speed, lattice, source, target);
    return passing;
}

} // namespace volmorph::detail
