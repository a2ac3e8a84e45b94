#include "blend/BlendMethod.h"

#include "blend/DensityBlend.h"
#include "blend/SdfBlend.h"
#include "blend/VariationalBlend.h"

#include <stdexcept>

namespace volmorph::detail {

std::unique_ptr<const BlendMethod> makeBlendMethod(const BlendSetup& setup)
{
    switch (setup.spec.mode) {
    case BlendMode::Density:
        return makeDensityBlend(setup);
    case BlendMode::Sdf:
        return makeSdfBlend(setup);
    case BlendMode::Variational:
        return makeVariationalBlend(setup);
    case BlendMode::Surface:
        throw std::logic_error("makeBlendMethod: surface mode blends no voxels (SceneSurface.h)");
    }
    throw std::logic_error("makeBlendMethod: unknown blend mode");
}

Vec3f blendedColorBackground(const VolumeSet& source, const VolumeSet& target, float tauColor)
{
    return (1.0f - tauColor) * source.color->background() + tauColor * target.color->background();
}

} // namespace volmorph::detail
