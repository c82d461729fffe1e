// Statistical tests of VrlSurfaceEstimator (part (c): one VRL lighting a
// surface point) in an unbounded homogeneous medium above a large diffuse
// plane z = 0 (facing +z; nothing else, so visibility is 1 above it), against an
// independent 1-D quadrature of
//   L = Tb Phi sigma_s int_0^L f_p(d, (x - v)/r) e^{-sigma_t r} (rho/pi) max(0, n.(v - x)/r) / r^2 dt,
// r = |x - v(t)|, written here in double precision in the angle seen from x
// (dt / r^2 = dtheta / h), or in t when x lies on the VRL's line (h = 0).
//
// Multiple comparisons: 10 configurations x 3 channels = 30 means at 3.5 SE
// (two-sided p = 4.7e-4 each): a correct estimator fails a seed with
// probability below 1.5% (Bonferroni). A dropped factor, a wrong phase
// direction or a wrong pdf moves a mean by tens of SE.
#include "render/vrl/vrl_surface_estimator.h"

#include "render/scene/scene.h"
#include "tests/support/single_light_setting.h"
#include "tests/support/statistics.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace vrl {
namespace {

using V3d = Imath::V3d;
using test::gaussLegendre;
constexpr double kPiD = test::kPiDouble;
constexpr double kSigmas = 3.5;
constexpr int kSamples = 200'000;
const Rgb kRho(0.7f, 0.5f, 0.3f);

constexpr auto toD = &test::toDouble;
constexpr auto hg = &test::henyeyGreenstein;
using Medium = test::MediumCoefficients;

std::unique_ptr<Scene> planeInMedium(const Medium& m) { return test::planeInMedium(m, kRho); }

// The surface point straight below `above`, seen from `eye`.
CameraPathSurface surfacePoint(const Scene& scene, const Vec3& onPlane, const Vec3& eye, const Rgb& throughput) {
    const Vec3 to = (onPlane - eye).normalized();
    const auto hit = scene.intersect(Ray{eye, to});
    EXPECT_TRUE(hit.has_value());
    return cameraPathSurface(scene, *hit, -to, 0, throughput, 0);
}

V3d quadrature(const Vrl& vrl, const CameraPathSurface& x, const Medium& m, int panels) {
    const V3d o = toD(vrl.origin), d = toD(vrl.direction), p = toD(x.hit.position), n(0, 0, 1);
    const V3d sigmaT = toD(m.sigmaS) + toD(m.sigmaA);
    const double L = vrl.length, delta = d.dot(p - o), h = ((p - o) - d * delta).length();
    const auto integrand = [&](double t) {  // everything but 1/r^2
        const V3d v = o + d * t, toV = v - p;
        const double r = toV.length();
        const V3d wi = toV / r;
        const double cosine = std::max(0.0, n.dot(wi));
        const V3d tr(std::exp(-sigmaT.x * r), std::exp(-sigmaT.y * r), std::exp(-sigmaT.z * r));
        return tr * (hg(m.g, -d.dot(wi)) * cosine / kPiD) / (r * r);
    };
    V3d integral;
    if (h > 1e-9) {
        integral = gaussLegendre([&](double theta) {
            const double t = delta + h * std::tan(theta);
            const double r2 = h * h + (t - delta) * (t - delta);
            return integrand(t) * (r2 / h);  // dt = r^2 / h dtheta
        }, std::atan2(-delta, h), std::atan2(L - delta, h), panels);
    } else {
        integral = gaussLegendre(integrand, 0.0, L, panels);
    }
    const V3d scale = toD(vrl.flux) * toD(m.sigmaS) * toD(kRho) * toD(x.throughput);
    return {integral.x * scale.x, integral.y * scale.y, integral.z * scale.z};
}

V3d reference(const Vrl& vrl, const CameraPathSurface& x, const Medium& m, const std::string& what) {
    const V3d coarse = quadrature(vrl, x, m, 64), fine = quadrature(vrl, x, m, 128);
    for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(fine[c] - coarse[c]), 1e-4 * std::abs(fine[c])) << what;
    return fine;
}

void expectUnbiased(const VrlSurfaceEstimator& estimator, const Vrl& vrl, const CameraPathSurface& x, const V3d& ref,
                    uint64_t seed, const std::string& what) {
    const test::SampleMean m = test::sampleMean(
        seed, kSamples, [&](Rng& rng) { return estimator.contribution(vrl, x, rng); }, what);
    test::expectMeanNear(m, ref, kSigmas, what);
    ASSERT_GT(ref[1], 0.0) << what << ": the configuration must receive light";
}

using test::makeVrl;

const Medium kGrey{Rgb(0.8f), Rgb(0.2f), 0.0f};
const Medium kChromatic{Rgb(0.4f, 0.8f, 1.4f), Rgb(0.2f, 0.1f, 0.05f), 0.0f};
const Medium kForward{Rgb(0.8f), Rgb(0.2f), 0.7f};

TEST(VrlSurfaceEstimator, UnbiasedForRandomVrlsAndMedia) {
    Rng rng(23, 0);
    int configuration = 0;
    for (const Medium& m : {kGrey, kGrey, kGrey, kChromatic, kForward, kForward}) {
        const auto scene = planeInMedium(m);
        const VrlSurfaceEstimator estimator(*scene, 1);
        const Vec3 onPlane(2 * rng.next() - 1, 2 * rng.next() - 1, 0.0f);
        const Vec3 eye = onPlane + Vec3(2 * rng.next() - 1, 2 * rng.next() - 1, 0.5f + rng.next());
        const CameraPathSurface x = surfacePoint(*scene, onPlane, eye, Rgb(0.4f + 0.6f * rng.next()));
        const Vec3 origin(2 * rng.next() - 1, 2 * rng.next() - 1, 0.1f + 1.5f * rng.next());
        const Vec3 direction(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1);
        const Vrl vrl = makeVrl(origin, direction, 0.2f + 1.3f * rng.next());
        const std::string what = "random " + std::to_string(configuration);
        expectUnbiased(estimator, vrl, x, reference(vrl, x, m, what), 100 + configuration, what);
        ++configuration;
    }
}

TEST(VrlSurfaceEstimator, DegenerateGeometryHasItsExactLimit) {
    const auto scene = planeInMedium(kGrey);
    const VrlSurfaceEstimator estimator(*scene, 1);
    const CameraPathSurface x = surfacePoint(*scene, Vec3(0.1f, -0.2f, 0.0f), Vec3(0.5f, 0.3f, 1.0f), Rgb(1.0f));
    const Vec3& p = x.hit.position;
    // x on the VRL's line, outside the segment: a VRL coming straight down that ends 0.3 above x.
    const Vrl onLine = makeVrl(p + Vec3(0.0f, 0.0f, 1.3f), Vec3(0.0f, 0.0f, -1.0f), 1.0f);
    expectUnbiased(estimator, onLine, x, reference(onLine, x, kGrey, "on the line"), 7, "on the line");
    // The same, slanted: x on the line of a VRL at 45 degrees.
    const Vrl slanted = makeVrl(p + Vec3(0.8f, 0.0f, 0.8f), Vec3(-1.0f, 0.0f, -1.0f), 0.9f);
    expectUnbiased(estimator, slanted, x, reference(slanted, x, kGrey, "slanted line"), 8, "slanted line");
    // Parallel to the surface, at 0.5 and at 1e-3 above it (grazing light).
    const Vrl parallel = makeVrl(p + Vec3(-0.5f, 0.2f, 0.5f), Vec3(1.0f, 0.0f, 0.0f), 1.0f);
    expectUnbiased(estimator, parallel, x, reference(parallel, x, kGrey, "parallel"), 9, "parallel");
    const Vrl grazing = makeVrl(p + Vec3(-0.5f, 0.2f, 1e-3f), Vec3(1.0f, 0.0f, 0.0f), 1.0f);
    expectUnbiased(estimator, grazing, x, reference(grazing, x, kGrey, "grazing"), 10, "grazing");
    // Zero length: exactly nothing.
    Rng rng(1, 0);
    EXPECT_EQ(estimator.contribution(makeVrl(p + Vec3(0.0f, 0.0f, 1.0f), Vec3(1.0f, 0.0f, 0.0f), 0.0f), x, rng),
              Rgb(0.0f));
    // A VRL ending on x (the integral diverges there): every sample stays finite.
    const Vrl touching = makeVrl(p + Vec3(0.3f, 0.0f, 0.6f), Vec3(-0.3f, 0.0f, -0.6f), 0.670820f);
    for (int i = 0; i < 10000; ++i) {
        const Rgb c = estimator.contribution(touching, x, rng);
        ASSERT_TRUE(isFinite(c) && minComponent(c) >= 0.0f);
    }
    // Entirely behind the one-sided surface: nothing.
    const Vrl behind = makeVrl(p + Vec3(0.0f, 0.0f, -0.5f), Vec3(1.0f, 1.0f, 0.0f), 1.0f);
    for (int i = 0; i < 1000; ++i) EXPECT_EQ(estimator.contribution(behind, x, rng), Rgb(0.0f));
}

}  // namespace
}  // namespace vrl
