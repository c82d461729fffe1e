// render/media/: participating media: the homogeneous medium (transmittance,
// distance sampling, spectral tracking) and its phase functions.
//
// HomogeneousMedium: constant RGB scattering/absorption coefficients (1/length)
// and a phase function. Chromatic media are handled by spectral MIS (one-sample
// balance heuristic over the RGB channels): a channel is picked uniformly, a
// distance drawn from its exponential, and the weight divides by the average
// pdf over channels, which keeps every channel unbiased when they differ.
#pragma once

#include "render/core/rgb.h"
#include "render/media/phase_function.h"

#include <string>

namespace vrl {

// Result of free-flight sampling along a segment of length tMax.
struct FreeFlightSample {
    float t;         // distance of the collision, or tMax if the segment was passed
    bool scattered;  // true: a real scattering event at t
    Rgb weight;      // multiply the path throughput by this (sigma_s T / pdf, or T / P)
};

// The floor of transmittance bounds and importances (transmittanceBound, vrl_importance.h):
// far below any estimate a render keeps, far above the smallest double.
inline constexpr double kTransmittanceBoundFloor = 1e-30;

class HomogeneousMedium {
public:
    // Throws std::invalid_argument for negative or non-finite coefficients.
    HomogeneousMedium(std::string name, const Rgb& sigmaS, const Rgb& sigmaA, PhaseFunction phase);

    const std::string& name() const { return name_; }
    const Rgb& sigmaS() const { return sigmaS_; }
    const Rgb& sigmaA() const { return sigmaA_; }
    const Rgb& sigmaT() const { return sigmaT_; }
    const PhaseFunction& phase() const { return phase_; }
    // No scattering at all (pure absorber or vacuum): free-flight sampling is skipped.
    bool isNonScattering() const { return isBlack(sigmaS_); }
    bool isChromatic() const { return sigmaT_.x != sigmaT_.y || sigmaT_.y != sigmaT_.z; }

    // True if a straight segment between two points of this medium stays inside it
    // (no other medium or vacuum in between): set by the scene when it knows.
    bool boundaryConvex() const { return boundaryConvex_; }
    void setBoundaryConvex(bool convex) { boundaryConvex_ = convex; }

    Rgb transmittance(float distance) const;
    // An upper bound of transmittance over every path of length >= distance, for
    // cluster bounds: floored at kTransmittanceBoundFloor per channel, so that a bound's
    // product of factors does not underflow to 0 where the estimate it bounds is a denormal.
    Rgb transmittanceBound(double distance) const;
    // Samples a collision distance along [0, tMax) (tMax may be infinite) from two uniforms.
    FreeFlightSample sampleFreeFlight(float tMax, float uChannel, float uDistance) const;
    // The densities behind sampleFreeFlight: collision at t < tMax, and passing tMax.
    float freeFlightPdf(float t) const;
    float passProbability(float tMax) const;

private:
    std::string name_;
    Rgb sigmaS_, sigmaA_, sigmaT_;
    PhaseFunction phase_;
    bool boundaryConvex_ = false;
};

}  // namespace vrl
