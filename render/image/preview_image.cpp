#include "render/image/preview_image.h"

#include "util/atomic_file.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace vrl {
namespace {

// sRGB opto-electronic transfer function of a linear value in [0, 1].
float linearToSrgb(float c) { return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; }

uint8_t toByte(float linear, float scale) {
    float c = linear * scale;
    c = std::isnan(c) ? 0.0f : std::clamp(c, 0.0f, 1.0f);
    return uint8_t(std::lround(linearToSrgb(c) * 255.0f));
}

}  // namespace

void writePreviewPng(const Image& image, const std::filesystem::path& png, float exposureStops) {
    if (image.width() <= 0 || image.height() <= 0)
        throw std::invalid_argument("writePreviewPng: empty image for '" + png.string() + "'");
    const float scale = std::exp2(exposureStops);
    std::vector<uint8_t> bytes(image.pixelCount() * 3);
    for (size_t i = 0; i < image.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c) bytes[3 * i + size_t(c)] = toByte(image[i][c], scale);

    const auto fail = [&](const std::string& message) {
        return std::runtime_error("cannot write preview '" + png.string() + "': " +
                                  (message.empty() ? std::string("unknown error") : message));
    };
    try {
        util::writeAtomically(png, [&](const std::filesystem::path& tmp) {
            auto output = OIIO::ImageOutput::create("png");
            if (!output) throw fail(OIIO::geterror());
            output->threads(1);  // no OIIO thread pool to tear down at exit (texture.cpp says why)
            OIIO::ImageSpec spec(image.width(), image.height(), 3, OIIO::TypeDesc::UINT8);
            spec.attribute("oiio:ColorSpace", "sRGB");
            if (!output->open(tmp.string(), spec)) throw fail(output->geterror());
            if (!output->write_image(OIIO::TypeDesc::UINT8, bytes.data())) {
                const std::string message = output->geterror();
                output->close();
                throw fail(message);
            }
            if (!output->close()) throw fail(output->geterror());
        });
    } catch (const std::filesystem::filesystem_error& e) {  // the rename
        throw fail(e.code().message());
    }
}

float autoExposure(const Image& image) {
    if (image.pixelCount() == 0) return 0.0f;
    std::vector<float> lum(image.pixelCount());
    for (size_t i = 0; i < lum.size(); ++i) {
        const float l = luminance(image[i]);
        lum[i] = std::isfinite(l) ? std::max(l, 0.0f) : 0.0f;
    }
    // Nearest-rank percentile: the smallest value with at least 99% of pixels at or below it.
    const size_t k = std::max<size_t>(1, size_t(std::ceil(0.99 * double(lum.size())))) - 1;
    std::nth_element(lum.begin(), lum.begin() + ptrdiff_t(k), lum.end());
    float reference = lum[k];
    if (reference <= 0.0f) reference = *std::max_element(lum.begin() + ptrdiff_t(k), lum.end());
    if (reference <= 0.0f) return 0.0f;
    return std::clamp(std::log2(0.9f / reference), -30.0f, 30.0f);
}

}  // namespace vrl
