// Image error metrics of a test image against a reference, computed on
// per-pixel luminance (rgb.h luminance()) with double accumulation.
// With R = reference luminance, I = test luminance, n = compared pixels and
// eps = kMetricEpsilon = 0.01:
//   RMSE          = sqrt( (1/n) sum (I - R)^2 )
//   relative RMSE = sqrt( (1/n) sum (I - R)^2 / (R^2 + eps) )
//   SMAPE         = (2/n) sum |R - I| / (|R| + |I| + eps)
// SMAPE follows Vibert et al. 2019, whose denominator is R + I + eps; for the
// non-negative luminances a renderer produces the two agree, and the absolute
// values keep the denominator positive if a pixel is negative. SMAPE lies in [0, 2).
#pragma once

#include "render/image/image.h"

#include <cstddef>

namespace vrl {

inline constexpr double kMetricEpsilon = 0.01;

struct ImageErrorMetrics {
    double rmse = 0.0;
    double relativeRmse = 0.0;
    double smape = 0.0;
    double meanReference = 0.0, meanTest = 0.0;  // mean luminances over the compared pixels
    size_t pixels = 0;           // n: pixels compared (those with a finite test value)
    size_t nonFinitePixels = 0;  // test pixels with a NaN or infinite component, left out of the sums
};

// Compares `test` to `reference`. When no pixel can be compared (empty images,
// or every test pixel non-finite) the three metrics are NaN.
// Throws std::invalid_argument("image sizes differ: 640x480 vs 320x240", reference
// size first) on a size mismatch, and naming the pixel if `reference` has a
// non-finite pixel (a reference must be clean).
ImageErrorMetrics compareImages(const Image& reference, const Image& test);

}  // namespace vrl
