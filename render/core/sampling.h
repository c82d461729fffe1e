// Direction sampling shared by the estimators and emitters: the uniform sphere
// (pdf 1/(4 pi)) and the cosine-weighted hemisphere around +z (pdf cos/pi), from
// two uniforms in [0, 1).
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

}  // namespace vrl
