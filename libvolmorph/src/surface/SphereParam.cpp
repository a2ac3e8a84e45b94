#include "SphereParam.h"

#include "SpherePredicates.h"
#include "SphereStretch.h"

// OpenMesh's property arrays default-construct its vectors, which GCC 12 takes for a read of
// uninitialized memory when they are inlined here (the warning is in the library's templates).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModProgMeshT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include <Eigen/LU>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace volmorph::detail {
namespace {

struct Traits : OpenMesh::DefaultTraits {
    using Point = OpenMesh::Vec3d;
    VertexAttributes(OpenMesh::Attributes::Status);
    EdgeAttributes(OpenMesh::Attributes::Status);
    FaceAttributes(OpenMesh::Attributes::Status);
};
using PolyMesh = OpenMesh::TriMesh_ArrayKernelT<Traits>;
using Collapse = OpenMesh::Decimater::ModProgMeshT<PolyMesh>::Info;

/// The mesh relaxed whole when it has grown by this factor since the last time.
constexpr double kSweepGrowth = 1.25;
/// Relaxation sweeps over the finished map.
constexpr int kFinalSweeps = 4;

PolyMesh openMesh(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles)
{
    PolyMesh mesh;
    for (const Vec3d& p : points) mesh.add_vertex(PolyMesh::Point(p.x(), p.y(), p.z()));
    for (const Vec3I& t : triangles)
        if (!mesh.add_face(PolyMesh::VertexHandle(int(t[0])), PolyMesh::VertexHandle(int(t[1])),
                           PolyMesh::VertexHandle(int(t[2])))
                 .is_valid())
            throw std::runtime_error("the spherical map needs a manifold mesh");
    return mesh;
}

/// Quadric decimation to a tetrahedron; the collapses in the order they were made.
std::vector<Collapse> simplify(PolyMesh& mesh)
{
    OpenMesh::Decimater::DecimaterT<PolyMesh> decimater(mesh);
    OpenMesh::Decimater::ModQuadricT<PolyMesh>::Handle quadric;
    OpenMesh::Decimater::ModProgMeshT<PolyMesh>::Handle record;
    decimater.add(quadric);
    decimater.add(record);
    decimater.initialize();
    decimater.decimate_to(4);
    std::vector<Collapse> out = decimater.module(record).infolist();
    if (mesh.n_vertices() - out.size() != 4)
        throw std::runtime_error(
            "the mesh simplifies to " + std::to_string(mesh.n_vertices() - out.size()) +
            " vertices, not a tetrahedron: it is not a closed genus-0 surface");
    return out;
}

/// The fan of `v`: its triangles as (b, c), (v, b, c) counter-clockwise.
Fan fanOf(const PolyMesh& mesh, uint32_t v)
{
    Fan fan;
    for (const auto h : mesh.voh_range(PolyMesh::VertexHandle(int(v)))) {
        if (mesh.is_boundary(h)) continue;
        fan.emplace_back(uint32_t(mesh.to_vertex_handle(h).idx()),
                         uint32_t(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)).idx()));
    }
    return fan;
}

/// The four remaining vertices at a regular tetrahedron's corners, turned the mesh's way.
void placeBase(const PolyMesh& mesh, std::vector<Vec3d>& directions)
{
    const double s = 1.0 / std::sqrt(3.0);
    const Vec3d corners[4] = {Vec3d(s, s, s), Vec3d(s, -s, -s), Vec3d(-s, s, -s), Vec3d(-s, -s, s)};
    std::vector<uint32_t> base;
    for (const auto v : mesh.vertices())
        if (!mesh.status(v).deleted()) base.push_back(uint32_t(v.idx()));
    for (int i = 0; i < 4; ++i) directions[base[i]] = corners[i];
    const Fan fan = fanOf(mesh, base[0]);
    const Vec3d& p = directions[base[0]];
    if (p.dot(directions[fan[0].first].cross(directions[fan[0].second])) < 0.0)
        std::swap(directions[base[2]], directions[base[3]]); // the mirror image
}

/// The deepest point of the kernel of v's ring (where v sees every ring edge on its left), the
/// centre of the largest circle inside it in the gnomonic projection about the ring's centre: the
/// best of the points where three of the ring's edge lines are equally far. None when the ring
/// does not fit in that hemisphere (coarse levels) or the kernel has no inside.
std::optional<Vec3d> kernelCentre(const std::vector<Vec3d>& dir, const Fan& fan)
{
    Vec3d c(0.0);
    for (const auto& [b, e] : fan) c += dir[b];
    if (!(c.length() > 1e-6)) return std::nullopt;
    c.normalize();
    Vec3d axis(0.0);
    axis[std::abs(c.x()) < 0.5 ? 0 : (std::abs(c.y()) < 0.5 ? 1 : 2)] = 1.0;
    const Vec3d e1 = c.cross(axis).unitSafe(), e2 = c.cross(e1);
    struct Line {
        Eigen::Vector2d n;
        double d; // inside: n.x >= d, |n| = 1
    };
    std::vector<Line> lines;
    for (const auto& [b, e] : fan) {
        if (dir[b].dot(c) < 0.05 || dir[e].dot(c) < 0.05) return std::nullopt;
        const Eigen::Vector2d pb(dir[b].dot(e1) / dir[b].dot(c), dir[b].dot(e2) / dir[b].dot(c));
        const Eigen::Vector2d pe(dir[e].dot(e1) / dir[e].dot(c), dir[e].dot(e2) / dir[e].dot(c));
        Eigen::Vector2d n(-(pe - pb).y(), (pe - pb).x()); // left of b -> e
        if (!(n.norm() > 0.0)) return std::nullopt;
        n.normalize();
        lines.push_back({n, n.dot(pb)});
    }
    double best = 0.0;
    Eigen::Vector2d at;
    const size_t m = lines.size();
    for (size_t i = 0; i < m; ++i)
        for (size_t j = i + 1; j < m; ++j)
            for (size_t k = j + 1; k < m; ++k) {
                Eigen::Matrix3d a;
                Eigen::Vector3d rhs;
                const size_t idx[3] = {i, j, k};
                for (int r = 0; r < 3; ++r) {
                    a.row(r) << lines[idx[r]].n.x(), lines[idx[r]].n.y(), -1.0;
                    rhs(r) = lines[idx[r]].d;
                }
                const Eigen::Vector3d x = a.fullPivLu().solve(rhs);
                if (!(x(2) > best) || !(a * x).isApprox(rhs, 1e-9)) continue;
                bool inside = true;
                for (const Line& l : lines)
                    inside = inside && l.n.dot(x.head<2>()) - l.d >= x(2) * (1 - 1e-9);
                if (inside) {
                    best = x(2);
                    at = x.head<2>();
                }
            }
    if (!(best > 0.0)) return std::nullopt;
    const Vec3d p = c + at.x() * e1 + at.y() * e2;
    return p / p.length();
}

/// Places v0, just split from v1, inside its ring's kernel: at the kernel's deepest point when
/// there is one to find, else a short way from v1 into the wedge between the two triangles they
/// share (the other triangles of v0 were v1's, so near v1 they keep their orientation).
void placeSplit(const StretchMesh& m, uint32_t v0, uint32_t v1, const Fan& fan)
{
    std::vector<Vec3d>& dir = *m.directions;
    if (const std::optional<Vec3d> centre = kernelCentre(dir, fan)) {
        dir[v0] = *centre;
        if (fanValid(m, v0, dir[v0], fan)) return;
    }
    const Vec3d& s1 = dir[v1];
    Vec3d wedge(0.0);
    double nearest = 2.0;
    for (const auto& [b, c] : fan) {
        if (b == v1) wedge += s1.cross(dir[c]) / s1.cross(dir[c]).length();
        if (c == v1) wedge += dir[b].cross(s1) / dir[b].cross(s1).length();
        if (b != v1) nearest = std::min(nearest, (dir[b] - s1).length());
    }
    for (double step = 0.25 * nearest; step > 1e-9 * nearest; step *= 0.5) {
        const Vec3d p = s1 + step * wedge / wedge.length();
        dir[v0] = p / p.length();
        if (fanValid(m, v0, dir[v0], fan)) return;
    }
    throw std::runtime_error("the spherical map found no place for vertex " + std::to_string(v0));
}

/// Relaxes every vertex in turn, each first moved to its ring's kernel centre when that lowers its
/// energy: a vertex squeezed against its ring's edges barely moves by small steps (on CGAL's
/// fandisk, long thin CAD triangles, a few such held nearly all the stretch: efficiency 0.004
/// without the jump, 0.41 with it).
void sweep(const PolyMesh& mesh, const StretchMesh& m, int iterations)
{
    std::vector<Vec3d>& dir = *m.directions;
    for (const auto vh : mesh.vertices()) {
        if (mesh.status(vh).deleted()) continue;
        const uint32_t v = uint32_t(vh.idx());
        const Fan fan = fanOf(mesh, v);
        if (const std::optional<Vec3d> centre = kernelCentre(dir, fan))
            if (fanEnergy(m, v, *centre, fan) < fanEnergy(m, v, dir[v], fan)) dir[v] = *centre;
        relaxVertex(m, v, fan, iterations);
    }
}

/// Undoes the collapses, last first, keeping the map one-to-one.
void refine(PolyMesh& mesh, const std::vector<Collapse>& collapses, const StretchMesh& m,
            Interrupter* interrupter)
{
    size_t live = 4;
    double nextSweep = 4.0 * kSweepGrowth;
    const size_t total = collapses.size();
    for (size_t k = total; k-- > 0;) {
        const Collapse& c = collapses[k];
        mesh.status(c.v0).set_deleted(false);
        mesh.vertex_split(c.v0, c.v1, c.vl, c.vr);
        const uint32_t v0 = uint32_t(c.v0.idx()), v1 = uint32_t(c.v1.idx());
        placeSplit(m, v0, v1, fanOf(mesh, v0));
        relaxVertex(m, v0, fanOf(mesh, v0), 4);
        relaxVertex(m, v1, fanOf(mesh, v1), 2);
        relaxVertex(m, v0, fanOf(mesh, v0), 2);
        if (double(++live) >= nextSweep) {
            throwIfInterrupted(interrupter, int(100 * (total - k) / (total + 1)));
            sweep(mesh, m, 1);
            nextSweep = double(live) * kSweepGrowth;
        }
    }
    for (int s = 0; s < kFinalSweeps; ++s) {
        throwIfInterrupted(interrupter);
        sweep(mesh, m, 2);
    }
}

/// The exact check on the grid the merge uses, and the total area.
void requireOneToOne(const std::vector<Vec3d>& directions, const std::vector<Vec3I>& triangles)
{
    double area = 0.0;
    for (const Vec3I& t : triangles) {
        const Vec3d &p = directions[t[0]], &q = directions[t[1]], &r = directions[t[2]];
        if (orientation(toGrid(p), toGrid(q), toGrid(r)) <= 0)
            throw std::logic_error("the spherical map turned a triangle over");
        area += sphericalArea(p, q, r);
    }
    if (std::abs(area - 4.0 * M_PI) > 1e-6)
        throw std::logic_error("the spherical map covers " + std::to_string(area) +
                               " steradians, not 4 pi");
}

} // namespace

SphereMap sphericalMap(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles,
                       Interrupter* interrupter)
{
    PolyMesh mesh = openMesh(points, triangles);
    const std::vector<Collapse> collapses = simplify(mesh);
    SphereMap out;
    out.directions.assign(points.size(), Vec3d(0.0));
    out.collapses = collapses.size();
    placeBase(mesh, out.directions);
    StretchMesh m{&points, &out.directions, StretchMesh::evenStretch(points, triangles)};
    refine(mesh, collapses, m, interrupter);
    requireOneToOne(out.directions, triangles);
    out.stretchEfficiency = stretchEfficiency(points, out.directions, triangles);
    return out;
}

} // namespace volmorph::detail

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
