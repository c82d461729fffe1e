#include "render/media/homogeneous_medium.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace vrl {

namespace {
void requireValidCoefficient(const std::string& medium, const char* what, const Rgb& value) {
    if (!isFinite(value) || minComponent(value) < 0.0f)
        throw std::invalid_argument("medium '" + medium + "': " + what + " must be finite and non-negative, got (" +
                                    std::to_string(value.x) + ", " + std::to_string(value.y) + ", " +
                                    std::to_string(value.z) + ")");
}
}  // namespace

HomogeneousMedium::HomogeneousMedium(std::string name, const Rgb& sigmaS, const Rgb& sigmaA, PhaseFunction phase)
    : name_(std::move(name)), sigmaS_(sigmaS), sigmaA_(sigmaA), sigmaT_(sigmaS + sigmaA), phase_(phase) {
    requireValidCoefficient(name_, "sigmaS", sigmaS);
    requireValidCoefficient(name_, "sigmaA", sigmaA);
}

Rgb HomogeneousMedium::transmittance(float distance) const {
    if (std::isinf(distance)) {
        return {sigmaT_.x > 0 ? 0.0f : 1.0f, sigmaT_.y > 0 ? 0.0f : 1.0f, sigmaT_.z > 0 ? 0.0f : 1.0f};
    }
    return exp(-sigmaT_ * distance);
}

float HomogeneousMedium::freeFlightPdf(float t) const {
    return average(sigmaT_ * transmittance(t));
}

Rgb HomogeneousMedium::transmittanceBound(double distance) const {
    const auto channel = [distance](float sigmaT) {
        return float(std::max(std::exp(-double(sigmaT) * std::max(distance, 0.0)), kTransmittanceBoundFloor));
    };
    return {channel(sigmaT_.x), channel(sigmaT_.y), channel(sigmaT_.z)};
}

float HomogeneousMedium::passProbability(float tMax) const { return average(transmittance(tMax)); }

FreeFlightSample HomogeneousMedium::sampleFreeFlight(float tMax, float uChannel, float uDistance) const {
    if (isNonScattering()) return {tMax, false, transmittance(tMax)};  // exact, no sampling noise
    const int channel = std::min(2, static_cast<int>(uChannel * 3.0f));
    const float sigma = sigmaT_[channel];
    const float t = sigma > 0.0f ? -std::log1p(-uDistance) / sigma : kInfinity;
    if (t < tMax) {
        const Rgb tr = transmittance(t);
        return {t, true, sigmaS_ * tr / average(sigmaT_ * tr)};
    }
    const Rgb tr = transmittance(tMax);
    const float pass = average(tr);
    if (pass <= 0.0f) return {tMax, false, Rgb(0.0f)};  // cannot happen in exact arithmetic
    return {tMax, false, tr / pass};
}

}  // namespace vrl
