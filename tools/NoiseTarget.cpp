#include "NoiseTarget.h"

#include "Common.h"

#include <cmath>
#include <cstdio>

namespace volmorph::cli {

std::string samplesAndNoise(const render::Image& image, int samples, double target)
{
    char text[160];
    const std::string noise =
        std::isfinite(image.noise) ? ", noise " + fmt(image.noise) : std::string();
    if (target > 0.0)
        std::snprintf(text, sizeof text, "%.1f samples per pixel of at most %d%s (target %s)",
                      image.meanSamples, samples, noise.c_str(), fmt(target).c_str());
    else
        std::snprintf(text, sizeof text, "%d samples%s", samples, noise.c_str());
    return text;
}

void addNoiseOption(CLI::App* sub, double& noise)
{
    sub->add_option("--noise", noise,
                    "noise target: the frame's relative RMSE (e.g. 0.01); adaptive sampling stops "
                    "there, --samples is the cap; 0 = exactly --samples samples")
        ->check(CLI::Validator(
            [](const std::string& text) -> std::string {
                double v = 0.0;
                try {
                    v = std::stod(text);
                } catch (const std::exception&) {
                    return "expected a number from 0 to 1, got " + text;
                }
                if (!(v >= 0.0 && v <= 1.0))
                    return "expected a noise target from 0 to 1 (the frame's relative RMSE), got " +
                           text;
                return "";
            },
            "FROM 0 TO 1"));
}

} // namespace volmorph::cli
