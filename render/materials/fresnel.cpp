#include "render/materials/fresnel.h"

#include <algorithm>
#include <cmath>

namespace vrl {

namespace {

float conductorChannel(float cosI, float eta, float k) {
    const float cos2 = cosI * cosI, sin2 = 1.0f - cos2, sin4 = sin2 * sin2;
    const float temp1 = eta * eta - k * k - sin2;
    const float a2pb2 = std::sqrt(std::max(0.0f, temp1 * temp1 + 4.0f * k * k * eta * eta));
    const float a = std::sqrt(std::max(0.0f, 0.5f * (a2pb2 + temp1)));
    const float term1 = a2pb2 + cos2, term2 = 2.0f * a * cosI;
    const float rs = term1 + term2 > 0.0f ? (term1 - term2) / (term1 + term2) : 1.0f;
    const float term3 = a2pb2 * cos2 + sin4, term4 = term2 * sin2;
    const float rp = term3 + term4 > 0.0f ? rs * (term3 - term4) / (term3 + term4) : rs;
    return std::clamp(0.5f * (rs + rp), 0.0f, 1.0f);
}

}  // namespace

Rgb fresnelConductor(float cosThetaI, const Rgb& eta, const Rgb& k) {
    const float cosI = std::min(std::abs(cosThetaI), 1.0f);
    return {conductorChannel(cosI, eta.x, k.x), conductorChannel(cosI, eta.y, k.y),
            conductorChannel(cosI, eta.z, k.z)};
}

float fresnelDiffuseReflectance(float eta) {
    if (!(eta > 0.0f) || eta == 1.0f) return 0.0f;
    if (eta < 1.0f) {
        const double inv = 1.0 / eta;
        return float(1.0 - (1.0 - fresnelDiffuseReflectance(float(inv))) / (inv * inv));
    }
    // 2 F(mu) mu is smooth on [0, 1] for eta > 1 (no critical angle): composite
    // Simpson with 256 intervals, in double.
    const auto integrand = [eta](double mu) {
        const double sin2T = (1.0 - mu * mu) / (double(eta) * eta), cosT = std::sqrt(1.0 - sin2T);
        const double rs = (mu - eta * cosT) / (mu + eta * cosT), rp = (eta * mu - cosT) / (eta * mu + cosT);
        return (rs * rs + rp * rp) * mu;  // 2 * F * mu
    };
    constexpr int kIntervals = 256;
    const double h = 1.0 / kIntervals;
    double sum = integrand(0.0) + integrand(1.0);
    for (int i = 1; i < kIntervals; ++i) sum += integrand(i * h) * (i % 2 ? 4.0 : 2.0);
    return std::clamp(float(sum * h / 3.0), 0.0f, 1.0f);
}

}  // namespace vrl
