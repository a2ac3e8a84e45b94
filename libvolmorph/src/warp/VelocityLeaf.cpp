#include "warp/VelocityLeaf.h"

#include <algorithm>
#include <vector>

namespace volmorph::detail {

/// Both sides' velocities on the leaf's lattice, 4 voxels apart: point (i, j, k) at origin + 4 (i,
/// j, k).
struct VelocityLattice {
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

/// The lattice's points (i, j, k in 0..2): its 8 corners, or the 19 others.
std::vector<openvdb::Coord> latticePoints(bool middles)
{
    std::vector<openvdb::Coord> out;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k)
                if ((i == 1 || j == 1 || k == 1) == middles) out.emplace_back(i, j, k);
    return out;
}

/// Points whose exact velocities are taken together: one call of the kernel (8 points to a vector).
struct Batch {
    static constexpr int kCapacity = 64;
    Vec3d p[kCapacity];
    Vec3d v[2][kCapacity]; ///< both sides' velocities
    bool ok[kCapacity];    ///< false where J is singular (a fold: the velocity is 0)
    int n = 0;

    /// Adds point p; returns its index.
    int add(const Vec3d& point)
    {
        p[n] = point;
        return n++;
    }
    /// Evaluates the points; false if any lies on a fold.
    bool run(const PointVelocities& kernel)
    {
        kernel.velocities(p, size_t(n), v[0], v[1], ok);
        return std::all_of(ok, ok + n, [](bool b) { return b; });
    }
};

} // namespace

void VelocityLeaf::fillExact(const openvdb::Coord& origin, const openvdb::util::NodeMask<3>& on,
                             Vec3f source[512], Vec3f target[512]) const
{
    auto it = on.beginOn();
    while (it) {
        Batch batch;
        openvdb::Index voxels[Batch::kCapacity];
        for (; it && batch.n < Batch::kCapacity; ++it) {
            const openvdb::Index n = it.pos();
            voxels[batch.add(at(origin, int(n >> 6), int((n >> 3) & 7), int(n & 7)))] = n;
        }
        batch.run(mPoints);
        for (int i = 0; i < batch.n; ++i) {
            source[voxels[i]] = Vec3f(batch.v[0][i]);
            target[voxels[i]] = Vec3f(batch.v[1][i]);
        }
    }
}

void VelocityLeaf::refine(const openvdb::Coord& origin, int c, double speed,
                          const VelocityLattice& coarse, const openvdb::util::NodeMask<3>& on,
                          Vec3f source[512], Vec3f target[512]) const
{
    const int ox = (c >> 2) * 4, oy = ((c >> 1) & 1) * 4, oz = (c & 1) * 4;
    // The 19 new lattice points and the 8 cells' centres, in one batch.
    Batch batch;
    int index[3][3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k)
                if (i == 1 || j == 1 || k == 1)
                    index[i][j][k] = batch.add(at(origin, ox + 2 * i, oy + 2 * j, oz + 2 * k));
    const int firstCheck = batch.n;
    for (int q = 0; q < 8; ++q)
        batch.add(
            at(origin, ox + 2 * (q >> 2) + 1, oy + 2 * ((q >> 1) & 1) + 1, oz + 2 * (q & 1) + 1));
    batch.run(mPoints);
    Vec3d fine[2][3][3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k)
                for (int s = 0; s < 2; ++s) {
                    if (i != 1 && j != 1 && k != 1) { // a point of the coarse lattice
                        fine[s][i][j][k] =
                            coarse.v[s][ox / 4 + i / 2][oy / 4 + j / 2][oz / 4 + k / 2];
                    } else if (!batch.ok[index[i][j][k]]) {
                        return fillExact(origin, on, source, target); // a fold
                    } else {
                        fine[s][i][j][k] = batch.v[s][index[i][j][k]];
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
        passed[q] = batch.ok[firstCheck + q];
        for (int s = 0; s < 2 && passed[q]; ++s)
            passed[q] = (interpolate(s, cell, half) - batch.v[s][firstCheck + q]).length() <=
                        mTolerance * speed;
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
                                const VelocityLattice& lattice, Vec3f source[512],
                                Vec3f target[512]) const
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
    VelocityLattice lattice;
    double speed = 0.0;
    // Evaluates the lattice points (i, j, k) `points` in `batch` with the points it holds; false
    // at a fold.
    auto evaluate = [&](const std::vector<openvdb::Coord>& points, Batch& batch) {
        const int base = batch.n;
        for (const openvdb::Coord& l : points)
            batch.add(at(origin, 4 * l.x(), 4 * l.y(), 4 * l.z()));
        if (!batch.run(mPoints)) return false;
        for (size_t i = 0; i < points.size(); ++i) {
            const openvdb::Coord& l = points[i];
            for (int s = 0; s < 2; ++s) {
                const Vec3d& v = batch.v[s][base + int(i)];
                lattice.v[s][l.x()][l.y()][l.z()] = v;
                speed = std::max(speed, v.length());
            }
        }
        return true;
    };
    // The 8 checks and the corners, then if needed the other 19 points.
    static const std::vector<openvdb::Coord> corners = latticePoints(false),
                                             middles = latticePoints(true);
    Batch first;
    for (int c = 0; c < 8; ++c) {
        const openvdb::Coord p = checkPoint(c);
        first.add(at(origin, p.x(), p.y(), p.z()));
    }
    if (!evaluate(corners, first)) { // a fold of the warp: no interpolation across it
        fillExact(origin, on, source, target);
        return 0;
    }
    Vec3d checks[2][8];
    for (int c = 0; c < 8; ++c)
        for (int s = 0; s < 2; ++s) checks[s][c] = first.v[s][c];
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
        Batch rest;
        if (!evaluate(middles, rest)) {
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
