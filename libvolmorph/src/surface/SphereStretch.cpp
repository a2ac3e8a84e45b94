#include "SphereStretch.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace volmorph::detail {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// 2 x (mesh area) x (L2 stretch)^2 / (mesh area) of the chord triangle (p0, p1, p2) onto
/// (q0, q1, q2): the squared Frobenius norm of the map's Jacobian, sum over corners of
/// (corner's edge dot product) x (opposite mesh edge)^2 / (4 chord area^2); and the chord area.
double jacobianNorm2(const Vec3d& p0, const Vec3d& p1, const Vec3d& p2, const Vec3d& q0,
                     const Vec3d& q1, const Vec3d& q2, double& chordArea)
{
    const Vec3d e01 = p1 - p0, e02 = p2 - p0, e12 = p2 - p1;
    chordArea = 0.5 * e01.cross(e02).length();
    const double sum = e01.dot(e02) * (q2 - q1).lengthSqr() - e01.dot(e12) * (q2 - q0).lengthSqr() +
                       e02.dot(e12) * (q1 - q0).lengthSqr();
    return sum / (4.0 * chordArea * chordArea);
}

Vec3d unit(const Vec3d& v)
{
    return v / v.length();
}

} // namespace

double StretchMesh::energy(uint32_t a, const Vec3d& pa, uint32_t b, uint32_t c) const
{
    const Vec3d& pb = (*directions)[b];
    const Vec3d& pc = (*directions)[c];
    const double det = pa.dot(pb.cross(pc));
    if (det < kMinTripleProduct) return kInfinity;
    const Vec3d& qa = (*points)[a];
    const Vec3d& qb = (*points)[b];
    const Vec3d& qc = (*points)[c];
    double chordArea = 0.0;
    const double j2 = jacobianNorm2(pa, pb, pc, qa, qb, qc, chordArea);
    const double shape = ((pb - pa).lengthSqr() + (pc - pa).lengthSqr() + (pc - pb).lengthSqr()) /
                         (4.0 * std::sqrt(3.0) * chordArea);
    // det / (2 chord area): the chord plane's distance from the centre, near 1 for a small
    // triangle and 0 for one whose corners lie on a great circle (flat on the sphere, however
    // large its chord triangle): the coarse levels' large triangles are kept from that too.
    const double height = det / (2.0 * chordArea);
    return (0.5 * (qb - qa).cross(qc - qa).length() * 0.5 * j2 + kShapeWeight * even * shape) /
           height;
}

double StretchMesh::evenStretch(const std::vector<Vec3d>& points,
                                const std::vector<Vec3I>& triangles)
{
    // An even map gives each triangle 4 pi / F of the sphere and stretches it by the mesh's
    // area over that: a stretch energy of (A / F)^2 / (4 pi / F) per triangle.
    double area = 0.0;
    for (const Vec3I& t : triangles)
        area += 0.5 * (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]).length();
    const double f = double(std::max<size_t>(triangles.size(), 1));
    return (area / f) * (area / f) / (4.0 * M_PI / f);
}

double fanEnergy(const StretchMesh& m, uint32_t v, const Vec3d& at, const Fan& fan)
{
    double e = 0.0;
    for (const auto& [b, c] : fan) {
        e += m.energy(v, at, b, c);
        if (e == kInfinity) break;
    }
    return e;
}

namespace {

/// The derivative of the fan's energy along `axis` (a tangent at `at`), by central differences
/// (one-sided next to a triangle about to turn over); 0 when neither side is allowed.
double slope(const StretchMesh& m, uint32_t v, const Vec3d& at, const Fan& fan, const Vec3d& axis,
             double h, double here)
{
    const double ahead = fanEnergy(m, v, unit(at + h * axis), fan);
    const double behind = fanEnergy(m, v, unit(at - h * axis), fan);
    if (ahead != kInfinity && behind != kInfinity) return (ahead - behind) / (2.0 * h);
    if (ahead != kInfinity) return (ahead - here) / h;
    if (behind != kInfinity) return (here - behind) / h;
    return 0.0;
}

} // namespace

bool relaxVertex(const StretchMesh& m, uint32_t v, const Fan& fan, int iterations)
{
    if (fan.empty()) return false;
    Vec3d p = (*m.directions)[v];
    double chord = 0.0;
    for (const auto& [b, c] : fan) chord += ((*m.directions)[b] - p).length();
    chord /= double(fan.size());
    bool moved = false;
    double here = fanEnergy(m, v, p, fan);
    for (int it = 0; it < iterations && here != kInfinity; ++it) {
        // A tangent basis at p: the axis p leans on least, crossed with p.
        Vec3d axis(0.0);
        const Vec3d a(std::abs(p.x()), std::abs(p.y()), std::abs(p.z()));
        axis[a.x() <= a.y() && a.x() <= a.z() ? 0 : (a.y() <= a.z() ? 1 : 2)] = 1.0;
        const Vec3d e1 = unit(p.cross(axis));
        const Vec3d e2 = p.cross(e1);
        const double h = 1e-5 * chord;
        const Vec3d g =
            slope(m, v, p, fan, e1, h, here) * e1 + slope(m, v, p, fan, e2, h, here) * e2;
        if (!(g.length() > 0.0)) break;
        const Vec3d down = -g / g.length();
        bool accepted = false;
        for (double step = 0.5 * chord; step > 1e-12 * chord; step *= 0.5) {
            const Vec3d x = unit(p + step * down);
            const double e = fanEnergy(m, v, x, fan);
            if (e < here) {
                p = x;
                here = e;
                accepted = true;
                break;
            }
        }
        if (!accepted) break;
        moved = true;
    }
    (*m.directions)[v] = p;
    return moved;
}

double stretchEfficiency(const std::vector<Vec3d>& points, const std::vector<Vec3d>& directions,
                         const std::vector<Vec3I>& triangles)
{
    double meshArea = 0.0, chordAreas = 0.0, stretch = 0.0;
    for (const Vec3I& t : triangles) {
        const Vec3d &q0 = points[t[0]], &q1 = points[t[1]], &q2 = points[t[2]];
        const double area = 0.5 * (q1 - q0).cross(q2 - q0).length();
        double chordArea = 0.0;
        const double j2 = jacobianNorm2(directions[t[0]], directions[t[1]], directions[t[2]], q0,
                                        q1, q2, chordArea);
        meshArea += area;
        chordAreas += chordArea;
        stretch += area * 0.5 * j2;
    }
    const double l2 = stretch / meshArea * chordAreas / meshArea;
    return 1.0 / l2;
}

double sphericalArea(const Vec3d& p, const Vec3d& q, const Vec3d& r)
{
    return 2.0 * std::atan2(p.dot(q.cross(r)), 1.0 + p.dot(q) + q.dot(r) + r.dot(p));
}

} // namespace volmorph::detail
