#include "blend/ExtraGrids.h"

#include <volmorph/core/Diagnostics.h>
#include <volmorph/Schedule.h>

#include <set>

namespace volmorph::detail {
namespace {

openvdb::GridBase::Ptr find(const VolumeSet& v, const std::string& name)
{
    const auto it = v.extras.find(name);
    return it == v.extras.end() ? nullptr : it->second;
}

std::set<std::string> names(const VolumeSet& source, const VolumeSet& target)
{
    std::set<std::string> all;
    for (const VolumeSet* v : {&source, &target})
        for (const auto& [name, grid] : v->extras) all.insert(name);
    return all;
}

} // namespace

template <typename GridT>
std::vector<ExtraGrids::Extra<GridT>>
ExtraGrids::pair(const VolumeSet& source, const VolumeSet& target, const BlendSpec& spec, double t)
{
    std::vector<Extra<GridT>> out;
    for (const std::string& name : names(source, target)) {
        Extra<GridT> e;
        e.name = name;
        e.source = openvdb::gridConstPtrCast<GridT>(find(source, name));
        e.target = openvdb::gridConstPtrCast<GridT>(find(target, name));
        if (!e.source && !e.target) continue; // the other type
        e.sourceBackground = (e.source ? e.source : e.target)->background();
        e.targetBackground = (e.target ? e.target : e.source)->background();
        const auto it = spec.grids.find(name);
        e.schedule = it == spec.grids.end() ? &spec.density : &it->second.schedule;
        e.tau = float(scheduleValue(*e.schedule, t));
        e.like = e.source ? openvdb::GridBase::ConstPtr(e.source) : e.target;
        out.push_back(std::move(e));
    }
    return out;
}

ExtraGrids::ExtraGrids(const VolumeSet& source, const VolumeSet& target, const BlendSpec& spec,
                       double t, const LocalTime* local)
    : mFloats(pair<openvdb::FloatGrid>(source, target, spec, t)),
      mVectors(pair<openvdb::Vec3SGrid>(source, target, spec, t)), mT(t),
      mLocal(local && local->active() ? local : nullptr), mXform(source.density->transform().copy())
{
}

void ExtraGrids::check(const VolumeSet& source, const VolumeSet& target, const BlendSpec& spec)
{
    const std::set<std::string> all = names(source, target);
    for (const std::string& name : all) {
        const openvdb::GridBase::Ptr a = find(source, name), b = find(target, name);
        if (a && b && a->type() != b->type())
            throw UserError(SourceLocation{"blend"},
                            "grid '" + name + "' is of type " + a->valueType() +
                                " in the source and " + b->valueType() +
                                " in the target; a carried grid must have one type");
    }
    for (const auto& [name, schedule] : spec.grids)
        if (!all.count(name)) {
            std::string carried;
            for (const std::string& n : all) carried += (carried.empty() ? "" : ", ") + n;
            const std::string near = closestMatch(name, {all.begin(), all.end()});
            throw UserError(schedule.where,
                            "blend.grids." + name + ": neither side carries a grid '" + name + "'" +
                                (near.empty() ? "" : "; did you mean '" + near + "'?") +
                                " (carried: " + (carried.empty() ? "none" : carried) + ")");
        }
}

uint64_t ExtraGrids::bytesPerLeaf(const VolumeSet& source, const VolumeSet& target)
{
    uint64_t bytes = 0;
    for (const std::string& name : names(source, target)) {
        const openvdb::GridBase::Ptr g =
            find(source, name) ? find(source, name) : find(target, name);
        bytes += g->isType<openvdb::Vec3SGrid>() ? 7 * 1024 : 3 * 1024; // values, mask, spare
    }
    return bytes;
}

ExtraLeaves ExtraGrids::make(const openvdb::Coord& origin) const
{
    ExtraLeaves out;
    for (const auto& e : mFloats)
        out.floats.push_back(std::make_unique<openvdb::FloatTree::LeafNodeType>(
            origin, (1.0f - e.tau) * e.sourceBackground + e.tau * e.targetBackground, false));
    for (const auto& e : mVectors)
        out.vectors.push_back(std::make_unique<openvdb::Vec3STree::LeafNodeType>(
            origin, (1.0f - e.tau) * e.sourceBackground + e.tau * e.targetBackground, false));
    return out;
}

ExtraGrids::Outputs ExtraGrids::outputs() const
{
    Outputs out;
    auto add = [&out](const auto& e, auto& trees) {
        using GridT = typename std::decay_t<decltype(*e.source)>;
        auto grid = GridT::create((1.0f - e.tau) * e.sourceBackground + e.tau * e.targetBackground);
        grid->setName(e.name);
        grid->setGridClass(e.like->getGridClass());
        grid->setVectorType(e.like->getVectorType());
        trees.push_back(&grid->tree());
        out.grids[e.name] = grid;
    };
    for (const auto& e : mFloats) add(e, out.trees.floats);
    for (const auto& e : mVectors) add(e, out.trees.vectors);
    return out;
}

} // namespace volmorph::detail
