#include "render/media/phase_function.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace vrl {

PhaseFunction PhaseFunction::henyeyGreenstein(float g) {
    if (!(g > -1.0f && g < 1.0f))
        throw std::invalid_argument("Henyey-Greenstein g must lie in (-1, 1), got " + std::to_string(g));
    // Below this the density differs from isotropic by < 3e-6 relative, and the
    // inverse CDF would lose its precision to cancellation: treat as isotropic.
    return PhaseFunction(std::abs(g) < kIsotropicBelow ? 0.0f : g);
}

PhaseFunction::ValueRange PhaseFunction::valueRange(double cosLow, double cosHigh) const {
    if (g_ == 0.0f) return {double(kInv4Pi), double(kInv4Pi)};  // evalCosine's value
    const double g = g_;
    const double numerator = (1.0 - g * g) / (4.0 * 3.14159265358979323846);
    const double cosNear = g > 0.0 ? cosHigh : cosLow, cosFar = g > 0.0 ? cosLow : cosHigh;
    const double near = 1.0 + g * g - 2.0 * g * cosNear - kDenominatorSlack;
    const double far = 1.0 + g * g - 2.0 * g * cosFar + kDenominatorSlack;
    const double high =
        near > 0.0 ? numerator / (near * std::sqrt(near)) * (1.0 + 1e-5) : std::numeric_limits<double>::infinity();
    return {numerator / (far * std::sqrt(far)) * (1.0 - 1e-5), high};
}

float PhaseFunction::sampleCosine(float u) const {
    if (g_ == 0.0f) return 1.0f - 2.0f * u;
    // Inverse CDF of HG in the propagation convention (cos = 1 is forward), in
    // double: the expression cancels for small |g|, and must stay exact so that
    // the pdf returned by sample() is the density actually sampled.
    const double g = g_;
    const double sq = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    return float(std::clamp((1.0 + g * g - sq * sq) / (2.0 * g), -1.0, 1.0));
}

PhaseSample PhaseFunction::sample(const Vec3& dirIn, const Vec2& u) const {
    const float cosTheta = sampleCosine(u.x);
    const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
    const Vec3 local = sphericalDirection(sinTheta, cosTheta, 2.0f * kPi * u.y);
    const Vec3 dirOut = Frame::fromNormal(dirIn).toWorld(local).normalized();
    return {dirOut, evalCosine(cosTheta)};
}

}  // namespace vrl
