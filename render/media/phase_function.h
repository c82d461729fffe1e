// PhaseFunction: isotropic or Henyey-Greenstein scattering distribution, a
// value type (no tables: both are sampled exactly). Directions are
// *propagation* directions: `dirIn` is where light travelled before the
// scattering event, `dirOut` after it, so g > 0 means forward scattering.
// eval() returns the density in 1/sr; it integrates to 1 over the sphere.
#pragma once

#include "render/core/geometry.h"

#include <cmath>

namespace vrl {

struct PhaseSample {
    Vec3 direction;  // dirOut, unit
    float pdf;       // equals eval(): sampling is exact
};

class PhaseFunction {
public:
    static constexpr float kIsotropicBelow = 1e-6f;  // |g| below this is isotropic

    static PhaseFunction isotropic() { return PhaseFunction(0.0f); }
    // g in (-1, 1); throws std::invalid_argument otherwise. |g| < kIsotropicBelow is isotropic.
    static PhaseFunction henyeyGreenstein(float g);

    float g() const { return g_; }
    bool isIsotropic() const { return g_ == 0.0f; }

    // Density for the cosine between propagation directions. Inline: the VRL
    // estimator calls it 18 times per estimate in an HG medium.
    float evalCosine(float cosTheta) const {
        if (g_ == 0.0f) return kInv4Pi;
        const float denom = 1.0f + g_ * g_ - 2.0f * g_ * cosTheta;
        return kInv4Pi * (1.0f - g_ * g_) / (denom * std::sqrt(denom));
    }
    float eval(const Vec3& dirIn, const Vec3& dirOut) const { return evalCosine(dirIn.dot(dirOut)); }

    // For the cluster bounds (lightcuts/): bounds, in double, of what evalCosine
    // returns in float for cosines in [cosLow, cosHigh]. HG is monotone in the
    // cosine (increasing for g > 0), so the extremes sit at the ends; the float
    // denominator 1 + g^2 - 2 g cos, off by a few 1e-7, is widened by
    // kDenominatorSlack either way, the numerator by 1e-5. `high` is +infinity
    // when the slack reaches (1 - |g|)^2 (|g| > 0.9985 near the peak).
    struct ValueRange {
        double low, high;
    };
    static constexpr double kDenominatorSlack = 2e-6;
    ValueRange valueRange(double cosLow, double cosHigh) const;
    // The largest |d ln f / d theta| over all angles theta: 3|g| / (1 - g^2), at
    // cos theta = 2g / (1 + g^2).
    double logSlopeBound() const { return 3.0 * std::abs(double(g_)) / (1.0 - double(g_) * double(g_)); }
    // 1 + the relative error of a float value whose denominator is off by kDenominatorSlack.
    double floatErrorFactor() const {
        const double q = 1.0 - std::abs(double(g_));
        return 1.0 + 3.0 * kDenominatorSlack / (q * q);
    }
    // Samples dirOut given dirIn from two uniform numbers in [0,1).
    PhaseSample sample(const Vec3& dirIn, const Vec2& u) const;
    // Samples the cosine alone (the azimuth is uniform).
    float sampleCosine(float u) const;

private:
    explicit PhaseFunction(float g) : g_(g) {}
    float g_;
};

}  // namespace vrl
