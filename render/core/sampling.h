// Direction sampling shared by the estimators and emitters: the uniform sphere
// (pdf 1/(4 pi)) and the cosine-weighted hemisphere around +z (pdf cos/pi), from
// two uniforms in [0, 1); and the power heuristic that weights two sampling
// strategies of one path (Veach 1997 §9.2.4, exponent 2).
#pragma once

#include "render/core/geometry.h"

#include <algorithm>
#include <cmath>

namespace vrl {

inline Vec3 uniformSphere(const Vec2& u) {
    const float z = 1.0f - 2.0f * u.x;
    return sphericalDirection(std::sqrt(std::max(0.0f, 1.0f - z * z)), z, 2.0f * kPi * u.y);
}

inline Vec3 cosineHemisphere(const Vec2& u) {
    const float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u.x))};
}

// Weight of strategy f for a path that f samples with density pdfF and g with pdfG
// (one sample each): pdfF^2 / (pdfF^2 + pdfG^2); the two weights sum to 1.
// Written in the ratio pdfG / pdfF so that tiny or huge densities do not under- or overflow.
inline float powerHeuristic(float pdfF, float pdfG) {
    if (!(pdfF > 0.0f)) return 0.0f;
    const float ratio = pdfG / pdfF;
    return 1.0f / (1.0f + ratio * ratio);
}

}  // namespace vrl
