#include "SphereOverlay.h"

#include <array>
#include <deque>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace volmorph::detail {
namespace {

uint64_t edgeKey(uint32_t u, uint32_t v)
{
    return uint64_t(std::min(u, v)) << 32 | std::max(u, v);
}

/// Triangle across each edge: across[3 t + k] is the neighbour across edge (t[k], t[k + 1]).
std::vector<uint32_t> neighbours(const std::vector<Vec3I>& triangles)
{
    std::unordered_map<uint64_t, uint32_t> directed;
    directed.reserve(triangles.size() * 3);
    for (uint32_t t = 0; t < triangles.size(); ++t)
        for (int k = 0; k < 3; ++k)
            directed.emplace(uint64_t(triangles[t][k]) << 32 | triangles[t][(k + 1) % 3], t);
    std::vector<uint32_t> across(triangles.size() * 3);
    for (uint32_t t = 0; t < triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            const auto it =
                directed.find(uint64_t(triangles[t][(k + 1) % 3]) << 32 | triangles[t][k]);
            if (it == directed.end())
                throw std::runtime_error("the spherical map has an edge without its twin");
            across[3 * t + k] = it->second;
        }
    return across;
}

/// One step of a region's boundary: a side's own vertex, or a crossing of source edge k with
/// target edge m (corner indices in the pair's two triangles).
struct Event {
    bool crossing = false;
    int k = 0, m = 0; ///< vertex: its corner (k in the source's, m in the target's sequence)
    bool enters = false;
};

class Builder {
public:
    Builder(const SphereTriangulation& a, const SphereTriangulation& b) : mA(a), mB(b)
    {
        const size_t n = a.directions.size() + b.directions.size();
        mOut.vertices.resize(n);
        mOut.grid.resize(n);
        mOut.directions.resize(n);
        mSeen.assign(n, false);
        for (uint32_t i = 0; i < a.directions.size(); ++i) mOut.grid[i] = a.directions[i];
        for (uint32_t j = 0; j < b.directions.size(); ++j)
            mOut.grid[a.directions.size() + j] = b.directions[j];
        for (size_t v = 0; v < n; ++v) mOut.directions[v] = fromGrid(mOut.grid[v]);
    }

    Overlay run();

private:
    uint32_t nA() const { return uint32_t(mA.directions.size()); }
    /// det(a_k a_{k+1} b_m)-style predicates with the global indices SoS needs.
    int sideOfTarget(const Vec3I& t, int k, uint32_t sourceVertex) const
    {
        const uint32_t r = t[k], s = t[(k + 1) % 3];
        return orientationSoS(mB.directions[r], nA() + r, mB.directions[s], nA() + s,
                              mA.directions[sourceVertex], sourceVertex);
    }
    int sideOfSource(const Vec3I& t, int k, uint32_t targetVertex) const
    {
        const uint32_t p = t[k], q = t[(k + 1) % 3];
        return orientationSoS(mA.directions[p], p, mA.directions[q], q, mB.directions[targetVertex],
                              nA() + targetVertex);
    }
    uint32_t locate(uint32_t sourceVertex, const std::vector<uint32_t>& across) const;
    bool region(uint32_t a, uint32_t b, std::vector<uint32_t>& ring);
    uint32_t vertexOf(const Event& e, bool onSource, uint32_t a, uint32_t b);
    void cut(const std::vector<uint32_t>& ring, uint32_t a, uint32_t b);

    const SphereTriangulation &mA, &mB;
    Overlay mOut;
    std::vector<bool> mSeen;
    std::unordered_map<uint64_t, std::unordered_map<uint64_t, uint32_t>> mCrossings;
};

uint32_t Builder::locate(uint32_t sourceVertex, const std::vector<uint32_t>& across) const
{
    uint32_t t = 0;
    for (size_t step = 0; step < 4 * mB.triangles.size() + 16; ++step) {
        int out = -1;
        for (int k = 0; k < 3 && out < 0; ++k) {
            const int kk = int((k + step) % 3); // rotate the first edge tried: no cycles
            if (sideOfTarget(mB.triangles[t], kk, sourceVertex) < 0) out = kk;
        }
        if (out < 0) return t;
        t = across[3 * t + out];
    }
    for (uint32_t u = 0; u < mB.triangles.size(); ++u) // a walk that cycles: scan
        if (sideOfTarget(mB.triangles[u], 0, sourceVertex) > 0 &&
            sideOfTarget(mB.triangles[u], 1, sourceVertex) > 0 &&
            sideOfTarget(mB.triangles[u], 2, sourceVertex) > 0)
            return u;
    throw std::runtime_error("a source vertex lies in no target triangle");
}

uint32_t Builder::vertexOf(const Event& e, bool onSource, uint32_t a, uint32_t b)
{
    const Vec3I &ta = mA.triangles[a], &tb = mB.triangles[b];
    if (!e.crossing) {
        const uint32_t v = onSource ? ta[e.k] : nA() + tb[e.m];
        if (!mSeen[v]) {
            mSeen[v] = true;
            OverlayVertex& o = mOut.vertices[v];
            o.kind = onSource ? OverlayVertex::Kind::Source : OverlayVertex::Kind::Target;
            o.sourceTriangle = a;
            o.targetTriangle = b;
            o.source[0] = onSource ? ta[e.k] : 0;
            o.target[0] = onSource ? 0 : tb[e.m];
        }
        return v;
    }
    const uint32_t p = ta[e.k], q = ta[(e.k + 1) % 3], r = tb[e.m], s = tb[(e.m + 1) % 3];
    auto [it, fresh] = mCrossings[edgeKey(p, q)].emplace(edgeKey(r, s), 0);
    if (!fresh) return it->second;
    it->second = uint32_t(mOut.vertices.size());
    OverlayVertex o;
    o.kind = OverlayVertex::Kind::Crossing;
    o.sourceTriangle = a;
    o.targetTriangle = b;
    o.source[0] = p;
    o.source[1] = q;
    o.target[0] = r;
    o.target[1] = s;
    mOut.vertices.push_back(o);
    // The crossing of the great circles, on the side where both arcs are (det(r, s, p) > 0: at
    // (p x q) x (r x s)).
    const Vec3d dp = fromGrid(mA.directions[p]), dq = fromGrid(mA.directions[q]);
    const Vec3d dr = fromGrid(mB.directions[r]), ds = fromGrid(mB.directions[s]);
    Vec3d x = dp.cross(dq).cross(dr.cross(ds));
    x.normalize();
    if (sideOfTarget(tb, e.m, p) < 0) x = -x;
    mOut.directions.push_back(x);
    mOut.grid.push_back(toGrid(x));
    ++mOut.crossings;
    return it->second;
}

bool Builder::region(uint32_t a, uint32_t b, std::vector<uint32_t>& ring)
{
    ring.clear();
    const Vec3I &ta = mA.triangles[a], &tb = mB.triangles[b];
    // side[k][m]: source corner k against target edge m; sideB[m][k]: target corner m against
    // source edge k (both > 0 on the inner side).
    int side[3][3], sideB[3][3];
    for (int k = 0; k < 3; ++k)
        for (int m = 0; m < 3; ++m) {
            side[k][m] = sideOfTarget(tb, m, ta[k]);
            sideB[m][k] = sideOfSource(ta, k, tb[m]);
        }
    bool inA[3], inB[3], crosses[3][3];
    int count = 0;
    for (int k = 0; k < 3; ++k) {
        inA[k] = side[k][0] > 0 && side[k][1] > 0 && side[k][2] > 0;
        inB[k] = sideB[k][0] > 0 && sideB[k][1] > 0 && sideB[k][2] > 0;
    }
    for (int k = 0; k < 3; ++k)
        for (int m = 0; m < 3; ++m) {
            // Arcs p->q (source edge k) and r->s (target edge m) cross iff det(r,s,p) =
            // -det(r,s,q) = -det(p,q,r) = det(p,q,s) in sign (the antipodal case excluded).
            const int rsp = side[k][m], rsq = side[(k + 1) % 3][m];
            const int pqr = sideB[m][k], pqs = sideB[(m + 1) % 3][k];
            crosses[k][m] = rsp == -rsq && pqr == -pqs && rsp == -pqr;
            count += crosses[k][m];
        }
    if (count == 0) {
        const bool aInside = inA[0] && inA[1] && inA[2], bInside = inB[0] && inB[1] && inB[2];
        if (!aInside && !bInside) return false;
        for (int c = 0; c < 3; ++c) ring.push_back(vertexOf({false, c, c, false}, aInside, a, b));
        return true;
    }
    // Each boundary in order: its vertices inside the other triangle and its crossings, the one
    // entering the other triangle first where an edge crosses twice.
    std::vector<Event> seqA, seqB;
    for (int k = 0; k < 3; ++k) {
        if (inA[k]) seqA.push_back({false, k, 0, false});
        const size_t first = seqA.size();
        for (int m = 0; m < 3; ++m)
            if (crosses[k][m]) seqA.push_back({true, k, m, side[k][m] < 0});
        if (seqA.size() - first == 2 && !seqA[first].enters)
            std::swap(seqA[first], seqA[first + 1]);
    }
    for (int m = 0; m < 3; ++m) {
        if (inB[m]) seqB.push_back({false, 0, m, false});
        const size_t first = seqB.size();
        for (int k = 0; k < 3; ++k)
            if (crosses[k][m]) seqB.push_back({true, k, m, sideB[m][k] < 0});
        if (seqB.size() - first == 2 && !seqB[first].enters)
            std::swap(seqB[first], seqB[first + 1]);
    }
    auto find = [](const std::vector<Event>& seq, const Event& x) {
        for (size_t i = 0; i < seq.size(); ++i)
            if (seq[i].crossing && seq[i].k == x.k && seq[i].m == x.m) return i;
        throw std::runtime_error("a crossing is on one boundary and not the other");
    };
    size_t start = 0;
    while (!(seqA[start].crossing && seqA[start].enters)) ++start;
    // Along the source's boundary while inside the target, along the target's while inside the
    // source, switching at each crossing.
    size_t pos = start;
    for (int guard = 0; guard < 16; ++guard) {
        ring.push_back(vertexOf(seqA[pos], true, a, b));
        for (pos = (pos + 1) % seqA.size(); !seqA[pos].crossing; pos = (pos + 1) % seqA.size())
            ring.push_back(vertexOf(seqA[pos], true, a, b));
        ring.push_back(vertexOf(seqA[pos], true, a, b));
        size_t posB = find(seqB, seqA[pos]);
        for (posB = (posB + 1) % seqB.size(); !seqB[posB].crossing; posB = (posB + 1) % seqB.size())
            ring.push_back(vertexOf(seqB[posB], false, a, b));
        pos = find(seqA, seqB[posB]);
        if (pos == start) return true;
    }
    throw std::runtime_error("a region of the overlay does not close");
}

void Builder::cut(const std::vector<uint32_t>& ringIn, uint32_t a, uint32_t b)
{
    std::vector<uint32_t> ring = ringIn;
    const std::vector<GridDirection>& g = mOut.grid;
    while (ring.size() > 3) {
        const size_t n = ring.size();
        bool clipped = false;
        for (size_t i = 0; i < n && !clipped; ++i) {
            const uint32_t u = ring[(i + n - 1) % n], v = ring[i], w = ring[(i + 1) % n];
            if (orientation(g[u], g[v], g[w]) <= 0) continue;
            bool empty = true; // no other corner inside or on the ear
            for (size_t j = 0; j < n && empty; ++j) {
                const uint32_t x = ring[j];
                if (x == u || x == v || x == w) continue;
                empty = !(orientation(g[u], g[v], g[x]) >= 0 &&
                          orientation(g[v], g[w], g[x]) >= 0 && orientation(g[w], g[u], g[x]) >= 0);
            }
            if (!empty) continue;
            mOut.triangles.push_back(Vec3I(u, v, w));
            ring.erase(ring.begin() + long(i));
            clipped = true;
        }
        if (!clipped) { // rounding made the region non-convex beyond an ear: a fan
            ++mOut.unclipped;
            for (size_t i = 1; i + 2 < ring.size(); ++i)
                mOut.triangles.push_back(Vec3I(ring[0], ring[i], ring[i + 1]));
            ring = {ring[0], ring[ring.size() - 2], ring.back()};
        }
    }
    mOut.triangles.push_back(Vec3I(ring[0], ring[1], ring[2]));
    mOut.regions.resize(mOut.triangles.size(), {a, b});
}

Overlay Builder::run()
{
    const std::vector<uint32_t> acrossA = neighbours(mA.triangles);
    const std::vector<uint32_t> acrossB = neighbours(mB.triangles);
    uint32_t seedA = 0;
    while (mA.triangles[seedA][0] != 0 && mA.triangles[seedA][1] != 0 &&
           mA.triangles[seedA][2] != 0)
        ++seedA;
    const uint32_t nB = uint32_t(mB.triangles.size());
    auto key = [nB](uint32_t a, uint32_t b) { return uint64_t(a) * nB + b; };
    std::unordered_set<uint64_t> visited;
    std::deque<std::pair<uint32_t, uint32_t>> queue;
    const uint32_t seedB = locate(0, acrossB);
    queue.emplace_back(seedA, seedB);
    visited.insert(key(seedA, seedB));
    std::vector<uint32_t> ring;
    while (!queue.empty()) {
        const auto [a, b] = queue.front();
        queue.pop_front();
        if (!region(a, b, ring)) continue;
        cut(ring, a, b);
        for (int k = 0; k < 3; ++k) {
            if (visited.insert(key(acrossA[3 * a + k], b)).second)
                queue.emplace_back(acrossA[3 * a + k], b);
            if (visited.insert(key(a, acrossB[3 * b + k])).second)
                queue.emplace_back(a, acrossB[3 * b + k]);
        }
    }
    for (size_t v = 0; v < mSeen.size(); ++v)
        if (!mSeen[v]) throw std::runtime_error("the overlay missed a vertex of an input");
    return std::move(mOut);
}

} // namespace

Overlay overlay(const SphereTriangulation& source, const SphereTriangulation& target)
{
    return Builder(source, target).run();
}

size_t invertedTriangles(const std::vector<GridDirection>& grid,
                         const std::vector<Vec3I>& triangles)
{
    size_t n = 0;
    for (const Vec3I& t : triangles) n += orientation(grid[t[0]], grid[t[1]], grid[t[2]]) <= 0;
    return n;
}

} // namespace volmorph::detail
