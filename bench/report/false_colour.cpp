#include "bench/report/false_colour.h"

#include "render/image/preview_image.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace vrl::report {

namespace {

// Viridis at eight stops (sRGB, 0..1), interpolated linearly.
constexpr std::array<std::array<float, 3>, 8> kRamp = {{{0.267f, 0.005f, 0.329f},
                                                        {0.275f, 0.194f, 0.496f},
                                                        {0.213f, 0.359f, 0.552f},
                                                        {0.153f, 0.498f, 0.558f},
                                                        {0.122f, 0.633f, 0.531f},
                                                        {0.288f, 0.758f, 0.428f},
                                                        {0.626f, 0.854f, 0.223f},
                                                        {0.993f, 0.906f, 0.144f}}};

float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

}  // namespace

float percentileValue(const Image& counts, float percentile) {
    std::vector<float> values;
    values.reserve(counts.pixelCount());
    for (const Rgb& p : counts.pixels())
        if (std::isfinite(p.x)) values.push_back(p.x);
    if (values.empty()) return 0.0f;
    const size_t k = std::min(values.size() - 1, size_t(std::clamp(percentile, 0.0f, 1.0f) * float(values.size() - 1)));
    std::nth_element(values.begin(), values.begin() + k, values.end());
    return values[k];
}

void writeFalseColourPng(const Image& counts, float clipAt, const std::filesystem::path& png) {
    Image picture(counts.width(), counts.height());
    for (int y = 0; y < counts.height(); ++y) {
        for (int x = 0; x < counts.width(); ++x) {
            const float v = counts.at(x, y).x;
            const float t = clipAt > 0.0f && std::isfinite(v) ? std::clamp(v / clipAt, 0.0f, 1.0f) : 0.0f;
            const float f = t * float(kRamp.size() - 1);
            const size_t i = std::min(kRamp.size() - 2, size_t(f));
            const float s = f - float(i);
            Rgb c;
            for (int k = 0; k < 3; ++k) c[k] = srgbToLinear(kRamp[i][k] * (1.0f - s) + kRamp[i + 1][k] * s);
            picture.at(x, y) = c;  // writePreviewPng applies the sRGB curve back
        }
    }
    writePreviewPng(picture, png, 0.0f);
}

}  // namespace vrl::report
