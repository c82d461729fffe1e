// Statistical tests of HomogeneousMedium: Beer-Lambert transmittance,
// free-flight sampling against its stated densities (chi-square), and the
// property the renderer relies on: spectral-MIS weights are unbiased per channel.
#include "render/core/rng.h"
#include "render/media/homogeneous_medium.h"

#include "tests/support/statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace vrl {
namespace {

using test::chiSquare;
using test::chiSquareCritical;
using test::ChiSquare;
using test::simpson;

HomogeneousMedium grey() { return {"grey", Rgb(0.8f), Rgb(0.2f), PhaseFunction::isotropic()}; }
HomogeneousMedium chromatic() {
    return {"chromatic", Rgb(0.5f, 1.0f, 2.0f), Rgb(0.1f, 0.2f, 0.05f), PhaseFunction::isotropic()};
}

FreeFlightSample sample(const HomogeneousMedium& medium, float tMax, Rng& rng) {
    const float uChannel = rng.next();
    return medium.sampleFreeFlight(tMax, uChannel, rng.next());
}

TEST(HomogeneousMediumTest, TransmittanceIsBeerLambert) {
    // Float exp against double exp: a few ulps, 1e-6 relative.
    for (const float d : {0.0f, 0.1f, 1.0f, 2.5f, 10.0f}) {
        const Rgb tr = chromatic().transmittance(d);
        for (int c = 0; c < 3; ++c) {
            const double expected = std::exp(-double(chromatic().sigmaT()[c]) * d);
            EXPECT_NEAR(tr[c], expected, 1e-6 * expected) << "d = " << d << ", channel " << c;
        }
    }
    EXPECT_EQ(chromatic().sigmaT(), Rgb(0.6f, 1.2f, 2.05f));
}

TEST(HomogeneousMediumTest, TransmittanceAtInfinity) {
    EXPECT_EQ(chromatic().transmittance(kInfinity), Rgb(0.0f));
    const HomogeneousMedium partlyClear("clear-red", Rgb(0.0f, 1.0f, 0.0f), Rgb(0.0f, 0.0f, 0.5f),
                                        PhaseFunction::isotropic());
    EXPECT_EQ(partlyClear.transmittance(kInfinity), Rgb(1.0f, 0.0f, 0.0f));
    const HomogeneousMedium vacuum("vacuum", Rgb(0.0f), Rgb(0.0f), PhaseFunction::isotropic());
    EXPECT_EQ(vacuum.transmittance(kInfinity), Rgb(1.0f));
}

TEST(HomogeneousMediumTest, FreeFlightHistogramMatchesPdf) {
    // Seed (10, medium), N = 10^6 distances along a segment of length 3. Bins: 30
    // equal bins over [0, 3) plus one for passes; expected counts are N times the
    // Simpson integral of freeFlightPdf over each bin (64 steps: the integrand is
    // smooth, error ~1e-10), and N * passProbability(3). Chi-square at 1e-4.
    // The pass count alone is also held to 4 binomial standard errors.
    constexpr int kSamples = 1'000'000, kBins = 30;
    constexpr float kTMax = 3.0f;
    int stream = 0;
    for (const HomogeneousMedium& medium : {grey(), chromatic()}) {
        std::vector<double> observed(kBins + 1, 0.0), expected(kBins + 1);
        Rng rng(10, stream++);
        for (int i = 0; i < kSamples; ++i) {
            const FreeFlightSample s = sample(medium, kTMax, rng);
            if (!s.scattered) {
                ASSERT_EQ(s.t, kTMax);
                observed[kBins] += 1;
                continue;
            }
            ASSERT_GE(s.t, 0.0f);
            ASSERT_LT(s.t, kTMax);
            observed[std::min(kBins - 1, int(s.t / kTMax * kBins))] += 1;
        }
        double total = 0;
        for (int b = 0; b < kBins; ++b) {
            const double p = simpson([&](double t) { return medium.freeFlightPdf(float(t)); }, kTMax * b / kBins,
                                     kTMax * (b + 1) / kBins, 64);
            expected[b] = kSamples * p;
            total += p;
        }
        const double pass = medium.passProbability(kTMax);
        expected[kBins] = kSamples * pass;
        // The two densities together must describe every outcome.
        EXPECT_NEAR(total + pass, 1.0, 1e-5) << medium.name();
        const ChiSquare chi = chiSquare(observed, expected);
        EXPECT_LT(chi.statistic, chiSquareCritical(chi.dof, 1e-4)) << medium.name() << ", dof " << chi.dof;
        EXPECT_NEAR(observed[kBins], expected[kBins], 4 * std::sqrt(kSamples * pass * (1 - pass))) << medium.name();
    }
}

// Per-channel mean and standard error of the free-flight weight, counting only
// collisions in [a, b) (or only passes when a < 0), zero otherwise.
struct ChannelMeans {
    std::array<double, 3> mean{}, se{};
};
ChannelMeans weightMeans(const HomogeneousMedium& medium, float tMax, double a, double b, uint64_t stream, int n) {
    std::array<double, 3> sum{}, sum2{};
    Rng rng(11, stream);
    for (int i = 0; i < n; ++i) {
        const FreeFlightSample s = sample(medium, tMax, rng);
        const bool counted = a < 0 ? !s.scattered : (s.scattered && s.t >= a && s.t < b);
        if (!counted) continue;
        for (int c = 0; c < 3; ++c) {
            sum[c] += s.weight[c];
            sum2[c] += double(s.weight[c]) * s.weight[c];
        }
    }
    ChannelMeans out;
    for (int c = 0; c < 3; ++c) {
        out.mean[c] = sum[c] / n;
        out.se[c] = std::sqrt(std::max(0.0, sum2[c] / n - out.mean[c] * out.mean[c]) / n);
    }
    return out;
}

// Integral of sigmaS exp(-sigmaT t) over [a, b) in channel c (b may be infinite).
double expectedScattering(const HomogeneousMedium& medium, int c, double a, double b) {
    const double s = medium.sigmaS()[c], t = medium.sigmaT()[c];
    if (s == 0) return 0;
    if (t == 0) return s * (b - a);
    return s / t * (std::exp(-t * a) - (std::isinf(b) ? 0.0 : std::exp(-t * b)));
}

// For each interval: the mean weight of collisions in it (or of passes) must
// equal the exact per-channel answer within 4 standard errors (N = 10^6 each,
// seed (11, interval index), SE from the sample variance).
void expectUnbiased(const HomogeneousMedium& medium, float tMax, const std::vector<std::pair<double, double>>& bins) {
    constexpr int kSamples = 1'000'000;
    for (size_t i = 0; i < bins.size(); ++i) {
        const auto [a, b] = bins[i];
        const ChannelMeans m = weightMeans(medium, tMax, a, b, i, kSamples);
        for (int c = 0; c < 3; ++c) {
            const double expected =
                a < 0 ? double(medium.transmittance(tMax)[c]) : expectedScattering(medium, c, a, b);
            EXPECT_NEAR(m.mean[c], expected, 4 * m.se[c] + 1e-12)
                << medium.name() << ", tMax " << tMax << ", channel " << c << ", collisions in [" << a << ", " << b
                << ") (a < 0: passes)";
        }
    }
}

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::pair<double, double> kPasses{-1.0, -1.0};

TEST(HomogeneousMediumTest, ChromaticWeightsAreUnbiasedOnFiniteSegment) {
    expectUnbiased(chromatic(), 3.0f, {{0.0, 0.5}, {0.5, 1.5}, {1.5, 3.0}, {0.0, 3.0}, kPasses});
}

TEST(HomogeneousMediumTest, ChromaticWeightsAreUnbiasedOnInfiniteSegment) {
    // Over [0, inf) the collision weights must sum to the albedo sigmaS/sigmaT.
    expectUnbiased(chromatic(), kInfinity, {{0.0, 1.0}, {1.0, 4.0}, {4.0, kInf}, {0.0, kInf}, kPasses});
    // A channel with sigmaT = 0 never collides and always passes an infinite segment.
    const HomogeneousMedium clearRed("clear-red", Rgb(0.0f, 1.0f, 0.5f), Rgb(0.0f, 0.5f, 0.5f),
                                     PhaseFunction::isotropic());
    expectUnbiased(clearRed, kInfinity, {{0.0, 1.0}, {0.0, kInf}, kPasses});
    expectUnbiased(clearRed, 2.0f, {{0.0, 1.0}, {1.0, 2.0}, kPasses});
}

TEST(HomogeneousMediumTest, PureAbsorberNeverScatters) {
    // No sampling noise: every sample passes with weight exp(-sigmaA tMax)
    // (float exp: 4 ulps). Seed (12, 0), 10^4 samples.
    const Rgb sigmaA(0.1f, 0.7f, 2.0f);
    const HomogeneousMedium absorber("ink", Rgb(0.0f), sigmaA, PhaseFunction::henyeyGreenstein(0.5f));
    EXPECT_TRUE(absorber.isNonScattering());
    Rng rng(12, 0);
    for (const float tMax : {0.0f, 0.3f, 3.0f, kInfinity}) {
        for (int i = 0; i < 10'000; ++i) {
            const FreeFlightSample s = sample(absorber, tMax, rng);
            ASSERT_FALSE(s.scattered);
            ASSERT_EQ(s.t, tMax);
            for (int c = 0; c < 3; ++c)
                ASSERT_FLOAT_EQ(s.weight[c], float(std::exp(-double(sigmaA[c]) * tMax))) << "tMax " << tMax;
        }
    }
}

TEST(HomogeneousMediumTest, InvalidCoefficientsThrowNamingMedium) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<std::pair<Rgb, Rgb>> invalid = {
        {Rgb(-0.1f, 1, 1), Rgb(0.0f)}, {Rgb(1.0f), Rgb(1, 1, -1e-6f)}, {Rgb(nan, 1, 1), Rgb(0.0f)},
        {Rgb(1.0f), Rgb(1, nan, 1)},   {Rgb(1, 1, kInfinity), Rgb(0.0f)}, {Rgb(1.0f), Rgb(-kInfinity, 0, 0)}};
    for (const auto& [sigmaS, sigmaA] : invalid) {
        try {
            HomogeneousMedium("fog-42", sigmaS, sigmaA, PhaseFunction::isotropic());
            ADD_FAILURE() << "no exception for sigmaS " << sigmaS << ", sigmaA " << sigmaA;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("fog-42"), std::string::npos) << e.what();
        }
    }
    EXPECT_NO_THROW(HomogeneousMedium("vacuum", Rgb(0.0f), Rgb(0.0f), PhaseFunction::isotropic()));
}

}  // namespace
}  // namespace vrl
