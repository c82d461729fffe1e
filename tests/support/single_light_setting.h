// The setting of the single-light estimator tests (one VRL lighting a surface
// point, one surface VPL lighting a camera segment, one VRL lighting a camera
// segment): an unbounded homogeneous medium, optionally above a large one-sided
// diffuse plane z = 0 facing +z (nothing else, so visibility is 1 above it), and
// the double-precision helpers their quadratures use. Header-only: each test
// links only what it uses.
#pragma once

#include "render/core/rng.h"
#include "render/scene/scene.h"
#include "render/vrl/vrl.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

namespace vrl::test {

inline constexpr double kPiDouble = 3.14159265358979323846;

// Coefficients of the homogeneous medium of these tests.
struct MediumCoefficients {
    Rgb sigmaS, sigmaA;
    float g;
};

inline Imath::V3d toDouble(const Vec3& v) { return {v.x, v.y, v.z}; }

// Henyey-Greenstein in double precision, per steradian.
inline double henyeyGreenstein(double g, double cosine) {
    const double denom = 1 + g * g - 2 * g * cosine;
    return (1 - g * g) / (4 * kPiDouble * denom * std::sqrt(denom));
}

// The medium everywhere, a point light at (0, 0, 5) (unused by these tests), and a
// one-sided diffuse square of side 200 at z = 0 facing +z with reflectance `rho`.
inline std::unique_ptr<Scene> planeInMedium(const MediumCoefficients& m, const Rgb& rho) {
    SceneDescription d = pointLightInInfiniteMedium(Rgb(1.0f), Vec3(0.0f, 0.0f, 5.0f), m.sigmaS, m.sigmaA, m.g);
    ShapeDescription plane;
    plane.kind = ShapeDescription::Kind::Rectangle;  // [-1,1]^2 at z = 0, facing +z
    plane.toWorld = Transform::scale(Vec3(100.0f));
    plane.bsdf = diffuseBsdf(rho, false);
    d.shapes.push_back(plane);
    return Scene::build(d);
}

// A VRL in medium 0 (the medium of these scenes), its direction normalised.
inline Vrl makeVrl(const Vec3& origin, const Vec3& direction, float length, const Rgb& flux = Rgb(1.0f, 0.8f, 0.6f)) {
    Vrl v;
    v.origin = origin;
    v.direction = direction.normalized();
    v.length = length;
    v.flux = flux;
    v.medium = 0;
    return v;
}

// The mean and standard error per channel of n draws of sample(rng), an Rgb, from
// Rng(seed, 0); every draw must be finite and >= 0 (a failure is reported, with
// `what`, and the rest of the draws skipped).
struct SampleMean {
    Imath::V3d mean{0.0}, standardError{0.0};
};
template <class Sample>
SampleMean sampleMean(uint64_t seed, int n, Sample&& sample, const std::string& what) {
    Rng rng(seed, 0);
    Imath::V3d sum(0.0), sumSq(0.0);
    for (int i = 0; i < n; ++i) {
        const Rgb c = sample(rng);
        if (!(isFinite(c) && minComponent(c) >= 0.0f)) {
            ADD_FAILURE() << what << ": draw " << i << " is negative or not finite";
            break;
        }
        sum += toDouble(c);
        sumSq += toDouble(c) * toDouble(c);
    }
    SampleMean m;
    for (int c = 0; c < 3; ++c) {
        m.mean[c] = sum[c] / n;
        m.standardError[c] = std::sqrt(std::max(0.0, sumSq[c] / n - m.mean[c] * m.mean[c]) / (n - 1));
    }
    return m;
}

// Each channel's mean within `sigmas` standard errors of `reference`, plus a
// relative slack of 1e-4 for the quadrature and float rounding.
inline void expectMeanNear(const SampleMean& m, const Imath::V3d& reference, double sigmas, const std::string& what) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(m.mean[c], reference[c], sigmas * m.standardError[c] + 1e-4 * std::abs(reference[c]))
            << what << " channel " << c << " SE " << m.standardError[c];
}

}  // namespace vrl::test
