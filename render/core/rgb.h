// Rgb: linear RGB radiometric quantity (radiance, flux, albedo, coefficients).
// Arithmetic is component-wise (Imath's Vec3 operators); helpers below add the
// few operations the renderer needs on spectra.
#pragma once

#include <Imath/ImathVec.h>

#include <algorithm>
#include <cmath>

namespace vrl {

using Rgb = Imath::V3f;

inline float luminance(const Rgb& c) { return 0.212671f * c.x + 0.715160f * c.y + 0.072169f * c.z; }
inline float maxComponent(const Rgb& c) { return std::max({c.x, c.y, c.z}); }
inline float minComponent(const Rgb& c) { return std::min({c.x, c.y, c.z}); }
// The channel-wise maximum of a and b.
inline Rgb componentMax(const Rgb& a, const Rgb& b) {
    return Rgb(std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z));
}
inline float average(const Rgb& c) { return (c.x + c.y + c.z) / 3.0f; }
inline bool isBlack(const Rgb& c) { return c.x == 0.0f && c.y == 0.0f && c.z == 0.0f; }
inline bool isFinite(const Rgb& c) { return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z); }
inline Rgb exp(const Rgb& c) { return {std::exp(c.x), std::exp(c.y), std::exp(c.z)}; }
inline Rgb rgbDivide(const Rgb& a, const Rgb& b) {
    return {b.x != 0 ? a.x / b.x : 0.0f, b.y != 0 ? a.y / b.y : 0.0f, b.z != 0 ? a.z / b.z : 0.0f};
}

}  // namespace vrl
