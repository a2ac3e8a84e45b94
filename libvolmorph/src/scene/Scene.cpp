// Value functions of the scene's settings; parsing lives in SceneParser.cpp and its table units.
#include <volmorph/Scene.h>

#include <volmorph/Frames.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>
#include <sstream>

namespace volmorph {

std::filesystem::path ObjectSpec::volumeAt(int frame) const
{
    if (!isSequence()) return volume;
    auto held = std::upper_bound(volumeFrames.begin(), volumeFrames.end(), frame);
    const int input = held == volumeFrames.begin() ? volumeFrames.front() : *std::prev(held);
    return frameFileName(volume.string(), input);
}

VolumeSource ObjectSpec::volumeSource() const
{
    return VolumeSource{volume, grids, window, transform, color, fileWhere};
}

Scene sceneAtFrame(const Scene& scene, int frame)
{
    Scene s = scene;
    for (ObjectSpec* o : {&s.source, &s.target})
        if (o->isSequence()) {
            o->volume = o->volumeAt(frame);
            o->volumeFrames.clear();
        }
    return s;
}

double FramesSpec::t(int frame) const
{
    if (last == first) return 0.0;
    return double(frame - first) / double(last - first);
}

} // namespace volmorph
