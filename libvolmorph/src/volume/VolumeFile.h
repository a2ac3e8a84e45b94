// One volume input's file: read whole once (core/VdbRead.h: a truncated file fails at once), the
// parts picked and checked (VolumeInput.h says how).
#pragma once

#include <volmorph/core/Diagnostics.h>
#include <volmorph/VolumeInput.h>
#include <volmorph/VolumeSource.h>

#include <openvdb/openvdb.h>

#include <memory>
#include <string>

namespace volmorph::detail {

class VolumeFile {
public:
    /// Reads `source.file` and picks its parts. Throws UserError (see VolumeInput).
    explicit VolumeFile(const VolumeSource& source);

    const VolumeFileInfo& info() const { return mInfo; }
    const VolumeSource& source() const { return mSource; }

    /// The grid `name`, placed: its transform followed by the object's.
    openvdb::GridBase::Ptr read(const std::string& name) const;

    /// A user error about this file, at the source's location (else the file), naming the file.
    UserError error(const std::string& what) const;

private:
    openvdb::GridBase::Ptr grid(const std::string& name) const;
    std::string pick(const std::string& part, const std::string& given,
                     std::initializer_list<const char*> defaults, bool vec3) const;
    void measure();

    VolumeSource mSource;
    openvdb::GridPtrVecPtr mGrids;
    VolumeFileInfo mInfo;
};

/// A grid's transform followed by the object's placement.
openvdb::math::Transform::Ptr placedTransform(const openvdb::math::Transform& grid,
                                              const ObjectTransform& object);

} // namespace volmorph::detail
