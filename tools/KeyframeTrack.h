// Animation of the scene's camera and lights: one keyframe track type for both. A track is the
// keys of one camera or light (Scene.h's CameraKey or LightKey: a frame and every value), held
// before the first key and after the last, and interpolated linearly between the two keys around
// a frame (directions renormalized). Frames may be fractional: a shutter's times between frames.
// Header-only: the CLI's SceneRender and the tests use it.
#pragma once

#include <volmorph/Scene.h>

#include <vector>

namespace volmorph::cli {

template <typename Key>
class KeyframeTrack {
public:
    /// `keys`: by increasing frame (the parser checks it); not empty.
    explicit KeyframeTrack(const std::vector<Key>& keys) : mKeys(keys) {}

    /// The two keys around `frame` and the weight u of the second; the same key twice outside
    /// them.
    struct Span {
        const Key* a;
        const Key* b;
        double u;

        /// The value of one member of the keys at the frame, linear between them.
        template <typename T>
        T operator()(T Key::*member) const
        {
            return lerp(a->*member, b->*member, u);
        }
        /// The same for a direction, renormalized.
        Vec3d direction(Vec3d Key::*member) const
        {
            return lerpDirection(a->*member, b->*member, u);
        }
    };
    Span at(double frame) const
    {
        Span s{&mKeys.front(), &mKeys.front(), 0.0};
        if (frame <= mKeys.front().frame) return s;
        s.a = s.b = &mKeys.back();
        if (frame >= mKeys.back().frame) return s;
        for (size_t i = 1; i < mKeys.size(); ++i) {
            if (frame <= mKeys[i].frame) {
                s.a = &mKeys[i - 1];
                s.b = &mKeys[i];
                s.u = double(frame - s.a->frame) / double(s.b->frame - s.a->frame);
                break;
            }
        }
        return s;
    }

    static double lerp(double a, double b, double u) { return a + (b - a) * u; }
    static Vec3d lerp(const Vec3d& a, const Vec3d& b, double u) { return a + (b - a) * u; }
    /// Linear interpolation of two directions, renormalized (keys may not be opposite: the
    /// parser refuses that).
    static Vec3d lerpDirection(const Vec3d& a, const Vec3d& b, double u)
    {
        const Vec3d d = lerp(a.unit(), b.unit(), u);
        return d.length() > 1e-12 ? d.unit() : a.unit();
    }

private:
    const std::vector<Key>& mKeys;
};

/// `spec` (a camera or a light) at `frame`: a copy without keys whose values `interpolate(copy,
/// span)` sets from the two keys around the frame; `spec` itself, less its keys, when it has none.
template <typename Spec, typename Interpolate>
Spec atFrame(const Spec& spec, double frame, const Interpolate& interpolate)
{
    using Key = typename decltype(spec.keys)::value_type;
    Spec out = spec;
    out.keys.clear();
    if (!spec.keys.empty()) interpolate(out, KeyframeTrack<Key>(spec.keys).at(frame));
    return out;
}

/// The camera at `frame`: its keys interpolated, up renormalized.
inline CameraSpec cameraAt(const CameraSpec& camera, double frame)
{
    return atFrame(camera, frame, [](CameraSpec& c, const KeyframeTrack<CameraKey>::Span& at) {
        c.eye = at(&CameraKey::eye);
        c.lookat = at(&CameraKey::lookat);
        c.up = at.direction(&CameraKey::up);
        c.fovDegrees = at(&CameraKey::fovDegrees);
        c.orthoWidth = at(&CameraKey::orthoWidth);
    });
}

/// The light at `frame`: its keys interpolated, direction renormalized.
inline LightSpec lightAt(const LightSpec& light, double frame)
{
    return atFrame(light, frame, [](LightSpec& l, const KeyframeTrack<LightKey>::Span& at) {
        l.direction = at.direction(&LightKey::direction);
        l.position = at(&LightKey::position);
        l.color = at(&LightKey::color);
        l.intensity = at(&LightKey::intensity);
    });
}

} // namespace volmorph::cli
