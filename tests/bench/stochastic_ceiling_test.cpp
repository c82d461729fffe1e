// The arithmetic of stochastic_bench --ceiling (bench/stochastic_ceiling.h): a node's
// variance against an exact enumeration of the draw-and-divide estimator, the ideal
// probabilities, and the ceiling N / N_eff against random cuts and probabilities.
#include "bench/stochastic_ceiling.h"

#include <gtest/gtest.h>

#include <numeric>
#include <random>
#include <vector>

using namespace vrl::bench;

namespace {

// Each VRL's estimate takes one of two values with probability 1/2.
struct TwoPoint {
    double low, high;
    EstimateMoments moments() const { return {0.5 * (low + high), 0.5 * (low * low + high * high)}; }
};

std::vector<TwoPoint> randomEstimates(std::mt19937& rng, size_t n) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<TwoPoint> out(n);
    for (auto& e : out) {
        const double mean = std::pow(u(rng), 3.0), spread = mean * 2.0 * u(rng);
        e = {mean - 0.5 * spread, mean + 0.5 * spread};  // spread <= 2 mean: both >= 0
    }
    return out;
}

std::vector<double> randomProbabilities(std::mt19937& rng, size_t n) {
    std::uniform_real_distribution<double> u(0.01, 1.0);
    std::vector<double> q(n);
    for (double& v : q) v = u(rng);
    const double total = std::accumulate(q.begin(), q.end(), 0.0);
    for (double& v : q) v /= total;
    return q;
}

std::vector<EstimateMoments> momentsOf(const std::vector<TwoPoint>& estimates) {
    std::vector<EstimateMoments> m;
    for (const auto& e : estimates) m.push_back(e.moments());
    return m;
}

}  // namespace

TEST(StochasticCeiling, NodeVarianceIsTheDrawAndDivideEstimatorsVariance) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 100; ++trial) {
        const auto estimates = randomEstimates(rng, 1 + trial % 9);
        const auto q = randomProbabilities(rng, estimates.size());
        // Exact enumeration: VRL i with probability q_i, then either value with 1/2.
        double first = 0.0, second = 0.0;
        for (size_t i = 0; i < estimates.size(); ++i)
            for (const double x : {estimates[i].low, estimates[i].high}) {
                const double y = x / q[i];
                first += 0.5 * q[i] * y, second += 0.5 * q[i] * y * y;
            }
        const double variance = second - first * first;
        EXPECT_NEAR(nodeVariance(momentsOf(estimates), q), variance, 1e-9 * std::max(1.0, variance)) << trial;
    }
}

TEST(StochasticCeiling, IdealProbabilitiesGiveTheLeastVariance) {
    std::mt19937 rng(11);
    for (int trial = 0; trial < 200; ++trial) {
        const auto m = momentsOf(randomEstimates(rng, 2 + trial % 7));
        const double ideal = idealNodeVariance(m);
        EXPECT_LE(ideal, nodeVariance(m, randomProbabilities(rng, m.size())) * (1.0 + 1e-12)) << trial;
        std::vector<double> q;
        double total = 0.0;
        for (const auto& e : m) q.push_back(std::sqrt(e.second)), total += q.back();
        for (double& v : q) v /= total;
        EXPECT_NEAR(nodeVariance(m, q), ideal, 1e-12 * std::max(1.0, ideal)) << trial;
    }
}

TEST(StochasticCeiling, NodeVarianceIsInfiniteWhenAContributingVrlCannotBeDrawn) {
    const std::vector<EstimateMoments> m = {{1.0, 2.0}, {0.5, 0.5}};
    EXPECT_TRUE(std::isinf(nodeVariance(m, std::vector<double>{1.0, 0.0})));
    // A VRL whose estimate is always 0 may have probability 0.
    const std::vector<EstimateMoments> zero = {{1.0, 2.0}, {0.0, 0.0}};
    EXPECT_DOUBLE_EQ(nodeVariance(zero, std::vector<double>{1.0, 0.0}), 1.0);
}

TEST(StochasticCeiling, NoCutBeatsTheCeiling) {
    // K sum_n V_n >= (sum_i s_i)^2 for every partition into K nodes and all probabilities;
    // one VRL per node is plain VRLs, whose variance is sum_i s_i^2.
    std::mt19937 rng(3);
    for (int trial = 0; trial < 300; ++trial) {
        const size_t n = 2 + size_t(trial % 40);
        const auto m = momentsOf(randomEstimates(rng, n));
        double deviations = 0.0, variances = 0.0;
        for (const auto& e : m) deviations += e.deviation(), variances += e.deviation() * e.deviation();
        const size_t k = 1 + std::uniform_int_distribution<size_t>(0, n - 1)(rng);
        std::vector<size_t> node(n);
        for (size_t i = 0; i < n; ++i) node[i] = i < k ? i : std::uniform_int_distribution<size_t>(0, k - 1)(rng);
        double total = 0.0, ideal = 0.0;
        for (size_t c = 0; c < k; ++c) {
            std::vector<EstimateMoments> leaves;
            for (size_t i = 0; i < n; ++i)
                if (node[i] == c) leaves.push_back(m[i]);
            total += nodeVariance(leaves, randomProbabilities(rng, leaves.size()));
            ideal += idealNodeVariance(leaves);
        }
        EXPECT_GE(double(k) * ideal, deviations * deviations * (1.0 - 1e-12)) << trial;
        EXPECT_GE(double(k) * total, deviations * deviations * (1.0 - 1e-12)) << trial;
        // One VRL per node: the variance is plain's.
        double single = 0.0;
        for (const auto& e : m) single += nodeVariance(std::vector<EstimateMoments>{e}, std::vector<double>{1.0});
        EXPECT_NEAR(single, variances, 1e-12 * std::max(1.0, variances)) << trial;
    }
}

TEST(StochasticCeiling, CeilingsOfOneSegment) {
    CeilingSums equal;
    equal.add(std::vector<EstimateMoments>(50, {1.0, 2.0}), 1.0);
    EXPECT_NEAR(equal.ceiling(50), 1.0, 1e-12);  // equally noisy VRLs: no cut saves anything
    EXPECT_NEAR(equal.uniformCeiling(50), 1.0, 1e-12);
    CeilingSums one;
    std::vector<EstimateMoments> m(50, {1.0, 1.0});  // exact estimates...
    m[7] = {1.0, 5.0};                                // ...but one
    one.add(m, 1.0);
    EXPECT_NEAR(one.ceiling(50), 50.0, 1e-12);  // one noisy VRL: up to N
    EXPECT_NEAR(one.uniformCeiling(50), 50.0, 1e-12);
}

TEST(StochasticCeiling, NoAllocationOverSegmentsBeatsTheCeiling) {
    // Segments of different noise and weight. Spending n_g estimates on segment g gives at
    // least sum_g w_g S_g^2 / n_g; scaled to plain's variance sum_g w_g P_g, every
    // allocation spends at least N G / ceiling, and the same n on every segment at least
    // N G / uniformCeiling. The allocation n_g ~ sqrt(w_g) S_g attains the ceiling.
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 200; ++trial) {
        const size_t n = 30, segmentCount = 1 + size_t(trial % 6);
        CeilingSums sums;
        std::vector<double> weight, s, s2;
        for (size_t g = 0; g < segmentCount; ++g) {
            auto m = momentsOf(randomEstimates(rng, n));
            if (trial % 3 == 0 && g == 0)  // one segment whose noise is all in one VRL
                for (size_t i = 1; i < n; ++i) m[i].second = m[i].mean * m[i].mean;
            weight.push_back(0.1 + 10.0 * u(rng));
            sums.add(m, weight.back());
            double a = 0.0, b = 0.0;
            for (const auto& e : m) a += e.deviation(), b += e.deviation() * e.deviation();
            s.push_back(a), s2.push_back(b);
        }
        double plain = 0.0;
        for (size_t g = 0; g < segmentCount; ++g) plain += weight[g] * s2[g];
        const auto spent = [&](const std::vector<double>& shape) {  // budget to reach plain's variance
            double variance = 0.0, total = 0.0;
            for (size_t g = 0; g < segmentCount; ++g) variance += weight[g] * s[g] * s[g] / shape[g], total += shape[g];
            return total * variance / plain;
        };
        const double plainBudget = double(n * segmentCount);
        for (int a = 0; a < 20; ++a) {
            std::vector<double> shape(segmentCount);
            for (double& v : shape) v = 0.01 + u(rng);
            EXPECT_GE(spent(shape), plainBudget / sums.ceiling(n) * (1.0 - 1e-12)) << trial;
        }
        const std::vector<double> same(segmentCount, 1.0);
        EXPECT_NEAR(spent(same), plainBudget / sums.uniformCeiling(n), 1e-9 * spent(same)) << trial;
        std::vector<double> best(segmentCount);
        for (size_t g = 0; g < segmentCount; ++g) best[g] = std::sqrt(weight[g]) * s[g];
        EXPECT_NEAR(spent(best), plainBudget / sums.ceiling(n), 1e-9 * spent(best)) << trial;
        EXPECT_GE(sums.ceiling(n), sums.uniformCeiling(n) * (1.0 - 1e-12)) << trial;
    }
}
