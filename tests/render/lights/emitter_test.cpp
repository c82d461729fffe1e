// Statistical tests of the emitters: emission samples carry the emitter's power
// on average, next-event samples integrate the radiance they stand for and
// pdfDirect is their density, the spot follows Mitsuba's falloff, and
// EmitterSampler picks in proportion to power.
#include "render/core/rng.h"
#include "render/lights/emitter.h"

#include "tests/support/statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <tuple>
#include <utility>
#include <vector>

namespace vrl {
namespace {

using test::chiSquare;
using test::chiSquareCritical;
using test::ChiSquare;

constexpr double kPiD = 3.14159265358979323846;

// Running per-channel mean and standard error of the mean.
struct MeanEstimate {
    std::array<double, 3> sum{}, sum2{};
    int n = 0;
    void add(const Rgb& x) {
        for (int c = 0; c < 3; ++c) sum[c] += x[c], sum2[c] += double(x[c]) * x[c];
        ++n;
    }
    double mean(int c) const { return sum[c] / n; }
    double se(int c) const { return std::sqrt(std::max(0.0, sum2[c] / n - mean(c) * mean(c)) / n); }
};

// The unit square [0,1]^2 at z = 0, facing +z, as two triangles.
TriangleMesh unitSquare() {
    return {{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)}, {}, {{0, 1, 2}, {0, 2, 3}}, {}};
}
// [0,3]x[0,1] at z = 0, facing +z: a fan of triangles of areas 0.45, 1.05, 0.9, 0.6.
TriangleMesh fanRectangle() {
    return {{Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(3, 0.3f, 0), Vec3(3, 1, 0), Vec3(1.2f, 1, 0), Vec3(0, 1, 0)},
            {},
            {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}},
            {}};
}

// Spot at (1, 2, 3) aimed at the origin.
const Vec3 kSpotPosition(1, 2, 3);
Transform spotFrame() { return Transform::lookAt(kSpotPosition, Vec3(0.0f), Vec3(0, 0, 1)); }
const Rgb kSpotIntensity(2.0f, 1.0f, 0.5f);

// Mitsuba's spot falloff, in double: 1 up to the beam, linear in angle to 0 at the cutoff.
double spotFalloff(double theta, double beam, double cutoff) {
    return theta <= beam ? 1.0 : theta >= cutoff ? 0.0 : (cutoff - theta) / (cutoff - beam);
}

TEST(EmitterTest, PointEmissionCarriesPowerExactly) {
    // Constant weight 4 pi I; directions uniform: each mean component is 0
    // within 4 SE (variance 1/3). Seed (20, 0), N = 10^5.
    const Rgb intensity(1, 2, 3);
    const auto light = makePointEmitter(Vec3(1, -2, 0.5f), intensity);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(light->power()[c], 4 * kPiD * intensity[c], 1e-6 * 4 * kPiD * intensity[c]);
    constexpr int kSamples = 100'000;
    Rng rng(20, 0);
    MeanEstimate dir;
    for (int i = 0; i < kSamples; ++i) {
        const EmissionSample s = light->sampleEmission(Vec2(rng.next(), rng.next()), Vec2(rng.next(), rng.next()));
        ASSERT_EQ(s.weight, light->power());
        ASSERT_EQ(s.ray.origin, Vec3(1, -2, 0.5f));
        ASSERT_NEAR(s.ray.direction.length(), 1.0, 1e-6);
        dir.add(s.ray.direction);
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(dir.mean(c), 0.0, 4 * std::sqrt(1.0 / 3.0 / kSamples));
}

TEST(EmitterTest, SpotEmissionMeanWeightIsPower) {
    // Seed (21, 0), N = 10^6; mean weight within 4 SE (sample variance) of power().
    // Every ray must leave within the 30 degree cutoff (float slack 1e-6).
    const auto light = makeSpotEmitter(spotFrame(), kSpotIntensity, 30.0f, 20.0f);
    const Vec3 axis = (-kSpotPosition).normalized();
    Rng rng(21, 0);
    MeanEstimate weight;
    for (int i = 0; i < 1'000'000; ++i) {
        const EmissionSample s = light->sampleEmission(Vec2(rng.next(), rng.next()), Vec2(rng.next(), rng.next()));
        ASSERT_EQ(s.ray.origin, kSpotPosition);
        ASSERT_GE(s.ray.direction.dot(axis), std::cos(30.0 * kPiD / 180) - 1e-6);
        weight.add(s.weight);
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(weight.mean(c), light->power()[c], 4 * weight.se(c)) << "channel " << c;
}

TEST(EmitterTest, SpotPowerMatchesFalloffIntegral) {
    // 2 pi I * integral of falloff(theta) sin(theta) over [0, cutoff], midpoint
    // rule with 10^5 steps split at the beam (error ~1e-11). power() integrates
    // the ramp with 64 midpoint steps: error (h^2/24)|f'(cutoff) - f'(beam)|,
    // 1.2e-4 relative for the 60 degree ramp, hence 2e-4 (a wrong formula or a
    // missing 2 pi is off by far more).
    for (const auto& [cutoffDeg, beamDeg] : {std::pair(30.0, 20.0), std::pair(45.0, 10.0), std::pair(60.0, 0.0),
                                           std::pair(90.0, 89.0)}) {
        const double cutoff = cutoffDeg * kPiD / 180, beam = beamDeg * kPiD / 180;
        double integral = 0;
        for (const auto& [a, b] : {std::pair(0.0, beam), std::pair(beam, cutoff)}) {
            constexpr int kSteps = 50'000;
            for (int i = 0; i < kSteps; ++i) {
                const double theta = a + (b - a) * (i + 0.5) / kSteps;
                integral += spotFalloff(theta, beam, cutoff) * std::sin(theta) * (b - a) / kSteps;
            }
        }
        const auto light = makeSpotEmitter(spotFrame(), kSpotIntensity, float(cutoffDeg), float(beamDeg));
        for (int c = 0; c < 3; ++c) {
            const double expected = 2 * kPiD * kSpotIntensity[c] * integral;
            EXPECT_NEAR(light->power()[c], expected, 2e-4 * expected) << "cutoff " << cutoffDeg << ", beam " << beamDeg;
        }
    }
}

TEST(EmitterTest, SpotWithBeamAtOrBeyondCutoffIsAHardCone) {
    // beamWidth >= cutoff leaves no ramp: power = 2 pi I (1 - cos cutoff).
    for (const float beamDeg : {30.0f, 40.0f}) {
        const auto light = makeSpotEmitter(spotFrame(), kSpotIntensity, 30.0f, beamDeg);
        for (int c = 0; c < 3; ++c) {
            const double expected = 2 * kPiD * kSpotIntensity[c] * (1 - std::cos(30.0 * kPiD / 180));
            EXPECT_NEAR(light->power()[c], expected, 1e-5 * expected) << "beam " << beamDeg;
        }
    }
}

TEST(EmitterTest, SpotDirectFollowsFalloffAndInverseSquare) {
    // Deterministic: reference points at angle alpha from the axis, distance 2.5.
    // Float geometry and acos: 1e-4 relative.
    const Transform frame = spotFrame();
    const auto light = makeSpotEmitter(frame, kSpotIntensity, 30.0f, 20.0f);
    const double d = 2.5;
    for (const double alphaDeg : {0.0, 10.0, 19.0, 20.3, 25.0, 29.0, 35.0, 90.0, 180.0}) {
        const double alpha = alphaDeg * kPiD / 180;
        const Vec3 local(float(std::sin(alpha)), 0.0f, float(std::cos(alpha)));
        const Vec3 reference = kSpotPosition + frame.applyVector(local) * float(d);
        const DirectLightSample s = light->sampleDirect(reference, Vec2(0.3f, 0.7f));
        EXPECT_EQ(s.position, kSpotPosition);
        EXPECT_NEAR(s.distance, d, 1e-5);
        EXPECT_NEAR((reference + s.direction * s.distance - kSpotPosition).length(), 0.0, 1e-5);
        const double f = spotFalloff(alpha, 20 * kPiD / 180, 30 * kPiD / 180);
        for (int c = 0; c < 3; ++c) {
            const double expected = kSpotIntensity[c] * f / (d * d);
            EXPECT_NEAR(s.weight[c], expected, 1e-4 * expected) << "alpha " << alphaDeg << " deg";
        }
    }
}

TEST(EmitterTest, AreaEmissionCarriesPowerFromUniformPositions) {
    // Weight is exactly power() = pi L A. Positions: chi-square (significance
    // 1e-4) over 0.25 x 0.25 cells, equal expected counts since sampling is
    // uniform in area; directions cosine-weighted: E[cos] = 2/3 within 4 SE.
    // Seed (22, mesh), N = 10^6 per mesh.
    const Rgb radiance(1.0f, 0.5f, 2.0f);
    int stream = 0;
    for (const auto& [mesh, width] : {std::pair(unitSquare(), 1), std::pair(fanRectangle(), 3)}) {
        const auto light = makeAreaEmitter(mesh, radiance);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(light->power()[c], kPiD * radiance[c] * width, 1e-6 * light->power()[c]);
        constexpr int kSamples = 1'000'000, kCellsPerUnit = 4;
        std::vector<double> observed(width * kCellsPerUnit * kCellsPerUnit, 0.0);
        double sumCos = 0, sumCos2 = 0;
        Rng rng(22, stream++);
        for (int i = 0; i < kSamples; ++i) {
            const EmissionSample s = light->sampleEmission(Vec2(rng.next(), rng.next()), Vec2(rng.next(), rng.next()));
            ASSERT_EQ(s.weight, light->power());
            const Vec3 p = s.ray.origin;
            ASSERT_TRUE(p.x > -1e-5f && p.x < width + 1e-5f && p.y > -1e-5f && p.y < 1 + 1e-5f && p.z == 0) << p;
            const int cx = std::min(width * kCellsPerUnit - 1, int(p.x * kCellsPerUnit));
            const int cy = std::min(kCellsPerUnit - 1, int(p.y * kCellsPerUnit));
            observed[cy * width * kCellsPerUnit + cx] += 1;
            ASSERT_GT(s.ray.direction.z, 0.0f);
            sumCos += s.ray.direction.z;
            sumCos2 += double(s.ray.direction.z) * s.ray.direction.z;
        }
        const std::vector<double> expected(observed.size(), double(kSamples) / observed.size());
        const ChiSquare chi = chiSquare(observed, expected);
        EXPECT_LT(chi.statistic, chiSquareCritical(chi.dof, 1e-4)) << "mesh width " << width;
        const double meanCos = sumCos / kSamples;
        EXPECT_NEAR(meanCos, 2.0 / 3.0, 4 * std::sqrt((sumCos2 / kSamples - meanCos * meanCos) / kSamples));
    }
}

// E = integral over the light of L cos_l cos_r / d^2 dA by the midpoint rule on
// a grid of 1000 cells per unit length (error ~1e-6 relative for d >= 0.6).
double irradianceQuadrature(double width, const Vec3& reference, const Imath::V3d& receiverNormal) {
    constexpr int kPerUnit = 1000;
    const Imath::V3d r(reference.x, reference.y, reference.z);
    double sum = 0;
    for (int i = 0; i < int(width * kPerUnit); ++i)
        for (int j = 0; j < kPerUnit; ++j) {
            const Imath::V3d toLight = Imath::V3d((i + 0.5) / kPerUnit, (j + 0.5) / kPerUnit, 0) - r;
            const double d2 = toLight.length2(), d = std::sqrt(d2);
            sum += (-toLight.z / d) * std::max(0.0, toLight.dot(receiverNormal) / d) / d2;
        }
    return sum / (double(kPerUnit) * kPerUnit);
}

TEST(EmitterTest, AreaDirectMatchesIrradianceQuadrature) {
    // Averaging weight * cos_r estimates E per channel. Seed (23, mesh), N = 10^6,
    // tolerance 4 SE from the sample variance. From behind, every weight is 0.
    const Rgb radiance(1.0f, 0.5f, 2.0f);
    const Imath::V3d tilted = Imath::V3d(0.3, 0, -1).normalized(), down(0, 0, -1);
    int stream = 0;
    for (const auto& [mesh, width, reference, normal] :
         {std::tuple(unitSquare(), 1, Vec3(0.2f, 0.7f, 0.8f), tilted),
          std::tuple(fanRectangle(), 3, Vec3(1.2f, 0.5f, 0.6f), down)}) {
        const auto light = makeAreaEmitter(mesh, radiance);
        Rng rng(23, stream++);
        MeanEstimate estimate;
        for (int i = 0; i < 1'000'000; ++i) {
            const DirectLightSample s = light->sampleDirect(reference, Vec2(rng.next(), rng.next()));
            ASSERT_NEAR((reference + s.direction * s.distance - s.position).length(), 0.0, 1e-5);
            const Imath::V3d dir(s.direction.x, s.direction.y, s.direction.z);
            estimate.add(s.weight * float(std::max(0.0, dir.dot(normal))));
        }
        const double e = irradianceQuadrature(width, reference, normal);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(estimate.mean(c), radiance[c] * e, 4 * estimate.se(c)) << "width " << width << ", channel " << c;
        for (int i = 0; i < 1000; ++i) {
            const Vec3 behind(rng.next() * width, rng.next(), -0.5f);
            EXPECT_EQ(light->sampleDirect(behind, Vec2(rng.next(), rng.next())).weight, Rgb(0.0f)) << behind;
        }
    }
}

// Solid angle of the part x0 <= x < x1 of a light on [0, width] x [0, 1] seen from
// `reference`: integral of |cos_l| / d^2 dA, same grid (x0, x1 on grid lines).
double solidAngleQuadrature(double x0, double x1, const Vec3& reference) {
    constexpr int kPerUnit = 1000;
    const Imath::V3d r(reference.x, reference.y, reference.z);
    double sum = 0;
    for (int i = int(std::lround(x0 * kPerUnit)); i < int(std::lround(x1 * kPerUnit)); ++i)
        for (int j = 0; j < kPerUnit; ++j) {
            const Imath::V3d toLight = Imath::V3d((i + 0.5) / kPerUnit, (j + 0.5) / kPerUnit, 0) - r;
            const double d2 = toLight.length2();
            sum += std::abs(toLight.z) / (std::sqrt(d2) * d2);
        }
    return sum / (double(kPerUnit) * kPerUnit);
}

TEST(EmitterTest, AreaPdfDirectIsTheDensityOfSampleDirect) {
    // pdfDirect at each sampled point equals the sample's pdf, and is its density:
    // E[1/pdf] over sampleDirect's points is the light's solid angle, and E[g/pdf]
    // for g = 1 on one half of the light (x < width/2) is that half's solid angle
    // (catches a density of the right total but the wrong shape across triangles
    // of different areas). Front and back references (sampleDirect picks points
    // from behind too, with weight 0). Seed (26, case), N = 10^6, tolerance 4 SE
    // from the sample variance plus 1e-5 relative for the quadrature.
    int stream = 0;
    for (const auto& [mesh, width, reference] :
         {std::tuple(unitSquare(), 1, Vec3(0.2f, 0.7f, 0.8f)), std::tuple(fanRectangle(), 3, Vec3(1.2f, 0.5f, 0.6f)),
          std::tuple(fanRectangle(), 3, Vec3(2.5f, 0.2f, -0.4f))}) {
        const auto light = makeAreaEmitter(mesh, Rgb(1.0f));
        Rng rng(26, stream++);
        MeanEstimate whole, half;
        for (int i = 0; i < 1'000'000; ++i) {
            const DirectLightSample s = light->sampleDirect(reference, Vec2(rng.next(), rng.next()));
            const float pdf = light->pdfDirect(reference, s.position, Vec3(0, 0, 1));
            ASSERT_GT(pdf, 0.0f);
            ASSERT_NEAR(s.pdf, pdf, 1e-5f * pdf);
            whole.add(Rgb(1.0f / pdf));
            half.add(Rgb(s.position.x < 0.5f * width ? 1.0f / pdf : 0.0f));
        }
        const double omega = solidAngleQuadrature(0, width, reference);
        const double omegaHalf = solidAngleQuadrature(0, 0.5 * width, reference);
        EXPECT_NEAR(whole.mean(0), omega, 4 * whole.se(0) + 1e-5 * omega) << "case " << stream;
        EXPECT_NEAR(half.mean(0), omegaHalf, 4 * half.se(0) + 1e-5 * omega) << "case " << stream;
    }
}

TEST(EmitterTest, DiracEmittersHaveNoDirectDensity) {
    // Point and spot lights are found by NEE alone: pdfDirect and the sample's pdf are 0.
    const auto point = makePointEmitter(Vec3(1, 2, 3), Rgb(1.0f));
    const auto spot = makeSpotEmitter(spotFrame(), kSpotIntensity, 30.0f, 20.0f);
    for (const Emitter* e : {point.get(), spot.get()}) {
        const DirectLightSample s = e->sampleDirect(Vec3(0.0f), Vec2(0.3f, 0.7f));
        EXPECT_GT(maxComponent(s.weight), 0.0f);
        EXPECT_EQ(s.pdf, 0.0f);
        EXPECT_EQ(e->pdfDirect(Vec3(0.0f), s.position, Vec3(0, 0, 1)), 0.0f);
    }
}

TEST(EmitterTest, SamplerPicksInProportionToLuminanceOfPower) {
    // Zero-power emitters first, in the middle and last must never be picked.
    // Seed (24, 0), N = 10^7 u values; frequencies by chi-square at 1e-4.
    const TriangleMesh square = unitSquare();
    std::vector<std::unique_ptr<Emitter>> owned;
    owned.push_back(makePointEmitter(Vec3(0.0f), Rgb(0.0f)));
    owned.push_back(makePointEmitter(Vec3(0.0f), Rgb(1, 0, 0)));
    owned.push_back(makeSpotEmitter(spotFrame(), kSpotIntensity, 30.0f, 20.0f));
    owned.push_back(makeAreaEmitter(square, Rgb(0, 1, 0)));
    owned.push_back(makeAreaEmitter(square, Rgb(0.0f)));
    owned.push_back(makePointEmitter(Vec3(0.0f), Rgb(0, 0, 3)));
    owned.push_back(makePointEmitter(Vec3(0.0f), Rgb(0.0f)));
    std::vector<const Emitter*> emitters;
    double total = 0;
    for (const auto& e : owned) emitters.push_back(e.get()), total += luminance(e->power());
    const EmitterSampler sampler(emitters);
    ASSERT_FALSE(sampler.empty());
    for (size_t i = 0; i < emitters.size(); ++i)
        EXPECT_NEAR(sampler.probability(i), luminance(emitters[i]->power()) / total, 1e-6) << "emitter " << i;
    constexpr int kSamples = 10'000'000;
    std::vector<double> observed(emitters.size(), 0.0), expected(emitters.size());
    Rng rng(24, 0);
    for (int i = 0; i < kSamples; ++i) {
        const auto [index, probability] = sampler.sample(rng.next());
        ASSERT_LT(index, emitters.size());
        ASSERT_EQ(probability, sampler.probability(index));
        observed[index] += 1;
    }
    for (size_t i = 0; i < emitters.size(); ++i) expected[i] = kSamples * luminance(emitters[i]->power()) / total;
    const ChiSquare chi = chiSquare(observed, expected);
    EXPECT_LT(chi.statistic, chiSquareCritical(chi.dof, 1e-4)) << "dof " << chi.dof;
    for (const float u : {0.0f, std::nextafter(1.0f, 0.0f)}) EXPECT_GT(sampler.sample(u).second, 0.0f) << u;
}

TEST(EmitterTest, SamplerWithOnlyBlackEmittersIsUniform) {
    // Seed (25, 0), N = 10^5: each of 4 bins expects 25000; chi-square at 1e-4.
    const TriangleMesh square = unitSquare();
    std::vector<std::unique_ptr<Emitter>> owned;
    owned.push_back(makePointEmitter(Vec3(0.0f), Rgb(0.0f)));
    owned.push_back(makeAreaEmitter(square, Rgb(0.0f)));
    owned.push_back(makeSpotEmitter(spotFrame(), Rgb(0.0f), 30.0f, 20.0f));
    owned.push_back(makePointEmitter(Vec3(1.0f), Rgb(0.0f)));
    std::vector<const Emitter*> emitters;
    for (const auto& e : owned) emitters.push_back(e.get());
    const EmitterSampler sampler(emitters);
    for (size_t i = 0; i < emitters.size(); ++i) EXPECT_FLOAT_EQ(sampler.probability(i), 0.25f);
    constexpr int kSamples = 100'000;
    std::vector<double> observed(emitters.size(), 0.0);
    Rng rng(25, 0);
    for (int i = 0; i < kSamples; ++i) {
        const auto [index, probability] = sampler.sample(rng.next());
        ASSERT_FLOAT_EQ(probability, 0.25f);
        observed[index] += 1;
    }
    const ChiSquare chi = chiSquare(observed, std::vector<double>(emitters.size(), kSamples / 4.0));
    EXPECT_LT(chi.statistic, chiSquareCritical(chi.dof, 1e-4));
    EXPECT_TRUE(EmitterSampler({}).empty());
}

}  // namespace
}  // namespace vrl
