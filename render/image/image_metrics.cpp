#include "render/image/image_metrics.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace vrl {
namespace {

std::string sizeOf(const Image& image) { return std::to_string(image.width()) + "x" + std::to_string(image.height()); }

bool finiteLuminance(const Rgb& c) { return isFinite(c) && std::isfinite(luminance(c)); }

}  // namespace

ImageErrorMetrics compareImages(const Image& reference, const Image& test) {
    if (reference.width() != test.width() || reference.height() != test.height())
        throw std::invalid_argument("image sizes differ: " + sizeOf(reference) + " vs " + sizeOf(test));

    ImageErrorMetrics metrics;
    double squaredError = 0.0, relativeSquaredError = 0.0, smapeSum = 0.0, referenceSum = 0.0, testSum = 0.0;
    for (int y = 0; y < reference.height(); ++y) {
        for (int x = 0; x < reference.width(); ++x) {
            if (!finiteLuminance(reference.at(x, y)))
                throw std::invalid_argument("reference image has a non-finite pixel at (" + std::to_string(x) +
                                            ", " + std::to_string(y) + ")");
            if (!finiteLuminance(test.at(x, y))) {
                ++metrics.nonFinitePixels;
                continue;
            }
            const double r = luminance(reference.at(x, y));
            const double i = luminance(test.at(x, y));
            const double difference = i - r;
            squaredError += difference * difference;
            relativeSquaredError += difference * difference / (r * r + kMetricEpsilon);
            smapeSum += std::abs(difference) / (std::abs(r) + std::abs(i) + kMetricEpsilon);
            referenceSum += r;
            testSum += i;
            ++metrics.pixels;
        }
    }

    if (metrics.pixels == 0) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        metrics.rmse = metrics.relativeRmse = metrics.smape = metrics.meanReference = metrics.meanTest = nan;
        return metrics;
    }
    const double n = double(metrics.pixels);
    metrics.rmse = std::sqrt(squaredError / n);
    metrics.relativeRmse = std::sqrt(relativeSquaredError / n);
    metrics.smape = 2.0 * smapeSum / n;
    metrics.meanReference = referenceSum / n;
    metrics.meanTest = testSum / n;
    return metrics;
}

}  // namespace vrl
