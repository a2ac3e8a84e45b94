// The blend methods' one choice of OpenVDB sampler, made where a method is created.
#pragma once

#include "blend/BlendMethod.h"

#include <openvdb/tools/Interpolation.h>

#include <memory>

namespace volmorph::detail {

template <template <class Sampler> class Method>
std::unique_ptr<const BlendMethod> withSampler(const BlendSetup& setup)
{
    if (setup.interpolation == Interpolation::Triquadratic)
        return std::make_unique<Method<openvdb::tools::QuadraticSampler>>(setup);
    return std::make_unique<Method<openvdb::tools::BoxSampler>>(setup);
}

} // namespace volmorph::detail
