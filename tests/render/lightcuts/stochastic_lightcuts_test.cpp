// Tests of stochastic VRL Lightcuts (stochastic_cut.h, vrl_importance.h,
// stochastic_lightcuts_estimator.h): unbiased against plain VRLs over the same VRL set.
//
// Reachability: for random trees and random camera segments (lines through
// node boxes, along a VRL's own line, starting inside the VRLs' region) and
// surface points, the exact path probability of every VRL under the chosen
// cut is computed; every VRL with non-zero flux and length has P > 0 for
// segments, and every VRL with P = 0 gives exactly 0 in 4 (segment) or 16
// (surface) samples (zero flux or length, or behind the surface); the
// probabilities sum to the cut's size (relative 1e-9: double rounding only).
//
// Unbiasedness, per query: one segment or surface point, the mean of 4,000
// stochastic estimates (cut size 8) against the mean of 64 plain sums over
// every VRL (each VRL's own one-sample estimator), within 4.5 combined
// standard errors (about 130 comparisons, fixed seeds: P(|z| > 4.5) = 7e-6 each
// for Gaussian means).
//
// Unbiasedness, per image: the renderer with one VRL set (traced once) and 64
// camera seeds for vrl-stochastic (8 for plain vrl, whose noise is a tenth of
// it), parts (c) and (d), image and 8x8 block means, in grey, chromatic and
// HG g = 0.7 media, with surfaces (the lit room) and without (the medium cube);
// within 5 combined standard errors of the seed means (Student t with 63 dof
// for the dominant term, P(|t| > 5) = 5e-6 each).
#include "render/lightcuts/cuts/stochastic_cut.h"
#include "render/lightcuts/cuts/stochastic_lightcuts_estimator.h"
#include "render/lightcuts/cuts/vrl_importance.h"
#include "render/renderer.h"
#include "render/scene/scene.h"
#include "render/vrl/vrl_estimator.h"
#include "render/vrl/vrl_surface_estimator.h"
#include "tests/support/test_scenes.h"
#include "tests/support/test_workload.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

namespace vrl {
namespace {

struct MediumCase {
    const char* name;
    Rgb sigmaS, sigmaA;
    float g;
};
const MediumCase kMedia[] = {{"grey", Rgb(0.8f), Rgb(0.2f), 0.0f},
                             {"chromatic", Rgb(0.4f, 0.8f, 1.4f), Rgb(0.2f, 0.1f, 0.05f), 0.0f},
                             {"hg0.7", Rgb(0.8f), Rgb(0.2f), 0.7f}};

Vec3 randomDirection(Rng& rng) {
    const float z = 2 * rng.next() - 1, phi = 6.2831853f * rng.next(), r = std::sqrt(std::max(0.0f, 1 - z * z));
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}

// A diffuse sphere of radius 1 at the origin in a medium filling the null-bounded
// cube [-4, 4]^3 (convex: the importance's T_r term is exercised).
std::unique_ptr<Scene> sphereInBoxedMedium(const MediumCase& m) {
    return Scene::build(
        test::sphereInMedium(m.sigmaS, m.sigmaA, m.g, test::diffuseBsdf(Rgb(0.7f, 0.5f, 0.3f), false), true));
}

// VRLs in [-3, 3]^3 outside the sphere mostly; every 10th of zero flux, every
// 7th of zero length, every 5th crossing the sphere's surface.
std::vector<Vrl> randomVrls(Rng& rng, int count) {
    std::vector<Vrl> vrls;
    for (int i = 0; i < count; ++i) {
        Vrl v;
        v.medium = 0;
        v.flux = i % 10 == 3 ? Rgb(0.0f) : Rgb(0.2f + rng.next(), 0.2f + rng.next(), 0.2f + rng.next()) * 1e-2f;
        v.origin = Vec3(6 * rng.next() - 3, 6 * rng.next() - 3, 6 * rng.next() - 3);
        v.direction = randomDirection(rng);
        v.length = i % 7 == 0 ? 0.0f : 0.05f + 1.5f * rng.next();
        if (i % 5 == 1) {
            const Vec3 onSphere = randomDirection(rng);
            v.origin = onSphere * 1.5f;
            v.direction = -onSphere;
            v.length = 0.5f;
        }
        vrls.push_back(v);
    }
    return vrls;
}

// Camera segments of every kind: generic, through a node's box centre, along a
// VRL's own line (h = 0 on its whole length), and starting inside the region.
CameraSegment randomSegment(const LightTree& tree, Rng& rng, int kind) {
    CameraSegment s;
    s.medium = 0;
    s.throughputBefore = Rgb(0.5f + 0.5f * rng.next());
    if (kind == 0) {
        s.origin = randomDirection(rng) * 3.9f;
        s.direction = (Vec3(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1) - s.origin).normalized();
    } else if (kind == 1) {
        const auto& node = tree.nodes()[size_t(rng.nextUint() % tree.nodes().size())];
        s.origin = randomDirection(rng) * 3.9f;
        s.direction = (node.box.center() - s.origin).normalized();
    } else if (kind == 2) {
        const Vrl& v = tree.vrls()[size_t(rng.nextUint() % tree.vrls().size())];
        s.origin = v.origin - v.direction * 0.5f;
        s.direction = v.direction;
    } else {
        s.origin = Vec3(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1) * 2.5f;
        s.direction = randomDirection(rng);
    }
    s.length = 0.5f + 6.0f * rng.next();
    return s;
}

std::optional<CameraPathSurface> randomSurfacePoint(const Scene& scene, Rng& rng) {
    const Vec3 eye = randomDirection(rng) * (1.2f + 2.0f * rng.next());
    const Vec3 target = randomDirection(rng) * 0.9f;
    const Vec3 dir = (target - eye).normalized();
    const auto hit = scene.intersect(Ray{eye, dir});
    if (!hit) return std::nullopt;
    return cameraPathSurface(scene, *hit, -dir, 0, Rgb(0.3f + 0.7f * rng.next()), 0);
}

double channelSum(const Rgb& c) { return double(c.x) + c.y + c.z; }

TEST(StochasticCut, EveryContributingVrlIsReachableAndProbabilitiesSumToTheCutSize) {
    uint64_t queries = 0, leavesChecked = 0, zeroProbability = 0;
    for (const MediumCase& m : kMedia) {
        const auto scene = sphereInBoxedMedium(m);
        Rng rng(11, uint64_t(&m - kMedia));
        const LightTree tree = LightTree::build(randomVrls(rng, 700), LightTreeSettings{128, 3});
        const VrlImportance importance(*scene, tree);
        const VrlSurfaceEstimator surfaceEstimator(*scene, 1);
        const VrlEstimator estimator(*scene, 1);
        for (const uint32_t cutSize : {1u, 8u, 64u}) {
            for (int q = 0; q < 24; ++q) {
                const CameraSegment segment = randomSegment(tree, rng, q % 4);
                const auto p = stochasticLeafProbabilities(
                    tree, cutSize, [&, q = importance.prepare(segment)](int32_t n) { return importance.children(n, q); });
                const auto cut = stochasticCut(tree, cutSize, [&, q = importance.prepare(segment)](int32_t n) { return importance.children(n, q); });
                double sum = 0.0;
                for (size_t k = 0; k < p.size(); ++k) {
                    sum += p[k];
                    ++leavesChecked;
                    const Vrl& vrl = tree.vrls()[k];
                    if (channelSum(vrl.flux) > 0.0 && vrl.length > 0.0f) {
                        EXPECT_GT(p[k], 0.0) << m.name << " segment " << q << " VRL " << k;
                    }
                    if (p[k] > 0.0) continue;
                    ++zeroProbability;
                    for (int s = 0; s < 4; ++s) {  // unreachable: it must give nothing
                        Rng sample(uint64_t(q), uint64_t(k * 16 + s));
                        EXPECT_EQ(channelSum(estimator.contribution(vrl, segment, sample)), 0.0)
                            << m.name << " segment " << q << " VRL " << k;
                    }
                }
                EXPECT_NEAR(sum, double(cut.size()), 1e-9 * double(cut.size())) << m.name << " segment " << q;
                EXPECT_EQ(cut.size(), std::min<size_t>(cutSize, tree.vrls().size()));
                ++queries;

                const auto x = randomSurfacePoint(*scene, rng);
                if (!x) continue;
                const auto ps = stochasticLeafProbabilities(
                    tree, cutSize, [&, q = importance.prepare(*x)](int32_t n) { return importance.children(n, q); });
                sum = 0.0;
                for (size_t k = 0; k < ps.size(); ++k) {
                    sum += ps[k];
                    ++leavesChecked;
                    if (ps[k] > 0.0) continue;
                    ++zeroProbability;
                    for (int s = 0; s < 16; ++s) {  // unreachable: it must give nothing
                        Rng sample(uint64_t(q), uint64_t(k * 16 + s));
                        EXPECT_EQ(channelSum(surfaceEstimator.contribution(tree.vrls()[k], *x, sample)), 0.0)
                            << m.name << " surface point " << q << " VRL " << k;
                    }
                }
                const auto cutS = stochasticCut(tree, cutSize, [&, q = importance.prepare(*x)](int32_t n) { return importance.children(n, q); });
                EXPECT_NEAR(sum, double(cutS.size()), 1e-9 * double(cutS.size())) << m.name << " surface " << q;
                ++queries;
            }
        }
    }
    std::printf("%llu queries, %llu (VRL, query) pairs, %llu unreachable (zero flux or length, or behind the "
                "surface; each checked to give 0)\n",
                (unsigned long long)queries, (unsigned long long)leavesChecked, (unsigned long long)zeroProbability);
    EXPECT_GT(zeroProbability, 0u) << "no VRL behind a surface point: the zero-importance case is not exercised";
}

// A child of importance 0 beside a positive sibling takes no slot of the cut: with a
// synthetic importance (the number of VRLs under a node on the positive-x side, so 0
// exactly where nothing under it contributes), every cut node holds a contributing VRL,
// the cut still has K nodes, every contributing VRL stays reachable and the
// probabilities sum to the cut's size. (Before, zero nodes kept their slots.)
TEST(StochasticCut, ZeroImportanceChildrenTakeNoSlot) {
    Rng rng(11, 0);
    const LightTree tree = LightTree::build(randomVrls(rng, 3000), LightTreeSettings{256, 11});
    std::vector<double> positive(tree.nodes().size(), 0.0);
    const auto countPositive = [&](auto&& self, int32_t node) -> double {
        const LightTreeNode& n = tree.nodes()[node];
        if (n.isLeaf()) return positive[node] = tree.vrls()[n.representative].origin.x > 0.0f ? 1.0 : 0.0;
        return positive[node] = self(self, n.left) + self(self, n.right);
    };
    countPositive(countPositive, tree.root());
    const auto importance = [&](int32_t n) {
        const LightTreeNode& node = tree.nodes()[n];
        return ChildImportances{{node.left, node.right}, {positive[node.left], positive[node.right]}};
    };
    for (const uint32_t cutSize : {2u, 16u, 64u, 256u}) {
        const std::vector<int32_t> cut = stochasticCut(tree, cutSize, importance);
        EXPECT_EQ(cut.size(), cutSize);
        for (const int32_t node : cut) EXPECT_GT(positive[node], 0.0) << "a cut node with nothing to contribute";
        const std::vector<double> p = stochasticLeafProbabilities(tree, cutSize, importance);
        double sum = 0.0;
        for (uint32_t k = 0; k < p.size(); ++k) {
            sum += p[k];
            if (tree.vrls()[k].origin.x > 0.0f) {
                EXPECT_GT(p[k], 0.0) << "contributing VRL " << k << " unreachable";
            } else {
                EXPECT_EQ(p[k], 0.0);
            }
        }
        EXPECT_NEAR(sum, double(cut.size()), 1e-9 * double(cut.size()));
    }
}

// forEachLeafDescent (which stochasticLeafProbabilities and stochastic_bench's
// --ceiling predictions are built on) gives the sampler's own probabilities: per
// draw of stochasticCutEstimate, with every leaf estimate 1, the total is the sum of
// 1 / P over the drawn leaves, and it must equal the sum of the predicted
// 1 / P(k | C) (relative 1e-6: the sampler adds them in float); and over
// 40,000 draws (Rng(14, t)) each leaf's frequency is within 5 binomial standard
// errors (+1e-9) of its predicted P(k | C). Each cut node's predictions sum to 1.
// Importances: flux x length times (1 + node % 3), so the branches are uneven.
TEST(StochasticCut, PredictedDescentProbabilitiesAreTheSamplersOwn) {
    Rng rng(14, 0);
    const LightTree tree = LightTree::build(randomVrls(rng, 60), LightTreeSettings{16, 14});
    const auto weight = [&](int32_t n) {
        const Rgb& fl = tree.nodes()[n].fluxLength;
        return (double(fl.x) + fl.y + fl.z) * (1.0 + n % 3);
    };
    const auto importance = [&](int32_t n) {
        const LightTreeNode& node = tree.nodes()[n];
        return ChildImportances{{node.left, node.right}, {weight(node.left), weight(node.right)}};
    };
    constexpr uint32_t kCutSize = 4;
    const std::vector<int32_t> cut = stochasticCut(tree, kCutSize, importance);
    ASSERT_EQ(cut.size(), kCutSize);
    std::vector<double> predicted(tree.vrls().size(), 0.0), ownImportance(tree.vrls().size(), -1.0);
    std::vector<LeafDescent> stack;
    for (const int32_t c : cut) {
        double sum = 0.0;
        forEachLeafDescent(
            tree, c, importance,
            [&](int32_t leaf, double q, double value) {
                predicted[size_t(leaf)] = q, ownImportance[size_t(leaf)] = value, sum += q;
            },
            stack);
        EXPECT_NEAR(sum, 1.0, 1e-12) << "cut node " << c;
    }
    // A leaf's own importance is its parent's pair's value for it (1 for a leaf in the cut).
    for (int32_t n = 0; n < int32_t(tree.nodes().size()); ++n) {
        if (isLeafNode(tree, n)) continue;
        for (const int32_t child : {tree.nodes()[n].left, tree.nodes()[n].right}) {
            if (isLeafNode(tree, child) && std::find(cut.begin(), cut.end(), child) == cut.end() &&
                ownImportance[size_t(child)] >= 0.0) {
                EXPECT_EQ(ownImportance[size_t(child)], weight(child)) << "leaf " << child;
            }
        }
    }
    constexpr int kDraws = 40'000;
    std::vector<int> drawn(tree.vrls().size(), 0);
    for (int t = 0; t < kDraws; ++t) {
        Rng draw(14, uint64_t(t) + 1);
        CutStatistics statistics;
        double expected = 0.0;
        const Rgb total = stochasticCutEstimate(tree, kCutSize, draw, statistics, importance,
                                                [&](const int32_t* leaves, size_t count, Rng&, Rgb* out) {
                                                    for (size_t k = 0; k < count; ++k) {
                                                        ++drawn[size_t(leaves[k])];
                                                        expected += 1.0 / predicted[size_t(leaves[k])];
                                                        out[k] = Rgb(1.0f);
                                                    }
                                                });
        ASSERT_NEAR(double(total.x), expected, 1e-6 * expected) << "draw " << t;
    }
    int reachable = 0;
    for (size_t k = 0; k < predicted.size(); ++k) {
        const double p = predicted[k], f = double(drawn[k]) / kDraws;
        reachable += p > 0.0;
        EXPECT_NEAR(f, p, 5.0 * std::sqrt(p * (1.0 - p) / kDraws) + 1e-9) << "leaf " << k;
    }
    EXPECT_GT(reachable, 40) << "too few leaves with a positive probability to test anything";
}

// The cut's skip rule (neverTaken) and the descent's probabilities (leftProbability)
// agree: over pairs of importances from {0, -0, a denormal, 1, 1e300, inf, NaN}, a
// child the cut skips has probability exactly 0 and its sibling 1; and a child of
// importance 0 that leftProbability gives probability 0 (its ratio branch) is skipped.
TEST(StochasticCut, SkippedChildrenAreTheOnesNoDescentTakes) {
    Rng rng(12, 0);
    const LightTree tree = LightTree::build(randomVrls(rng, 8), LightTreeSettings{4, 12});
    const LightTreeNode& root = tree.nodes()[tree.root()];
    const double values[] = {0.0, -0.0, 4.9e-324, 1.0, 1e300, std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::quiet_NaN()};
    int skipped = 0;
    for (const double l : values)
        for (const double r : values) {
            const ChildImportances c{{root.left, root.right}, {l, r}};
            const double pl = leftProbability(c, tree);
            const double p[2] = {pl, 1.0 - pl};
            for (int k = 0; k < 2; ++k) {
                SCOPED_TRACE(testing::Message() << "importances " << l << ", " << r << ", child " << k);
                if (neverTaken(c, k)) {
                    ++skipped;
                    EXPECT_EQ(p[k], 0.0);
                    EXPECT_EQ(p[1 - k], 1.0);
                }
                const double sum = c.value[0] + c.value[1];
                if (c.value[k] == 0.0 && sum > 0.0 && std::isfinite(sum)) {
                    EXPECT_TRUE(neverTaken(c, k));
                }
            }
        }
    EXPECT_EQ(skipped, 2 * 2 * 3) << "a zero beside the denormal, 1 and 1e300, either side";
    // In a cut: a 0 beside an infinite sibling keeps its slot (the descent falls back to
    // flux x length there), so every VRL of positive flux x length stays reachable and the
    // probabilities sum to K.
    const LightTree big = LightTree::build(randomVrls(rng, 500), LightTreeSettings{64, 12});
    const auto zeroBesideInfinite = [&](int32_t n) {
        const LightTreeNode& node = big.nodes()[n];
        return ChildImportances{{node.left, node.right}, {0.0, std::numeric_limits<double>::infinity()}};
    };
    for (const uint32_t cutSize : {4u, 32u}) {
        const std::vector<double> p = stochasticLeafProbabilities(big, cutSize, zeroBesideInfinite);
        double sum = 0.0;
        for (uint32_t k = 0; k < p.size(); ++k) {
            sum += p[k];
            const Vrl& v = big.vrls()[k];
            if (maxComponent(v.flux) > 0.0f && v.length > 0.0f) {
                EXPECT_GT(p[k], 0.0) << "VRL " << k << " unreachable at K = " << cutSize;
            }
        }
        EXPECT_NEAR(sum, double(cutSize), 1e-9 * cutSize);
    }
}

struct MeanAndError {
    Rgb mean{0.0f}, standardError{0.0f};
};

template <class Draw>
MeanAndError meanOf(int n, Draw&& draw) {
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
        const Rgb v = draw(i);
        for (int c = 0; c < 3; ++c) sum[c] += v[c], sum2[c] += double(v[c]) * v[c];
    }
    MeanAndError r;
    for (int c = 0; c < 3; ++c) {
        const double mean = sum[c] / n;
        r.mean[c] = float(mean);
        r.standardError[c] = float(std::sqrt(std::max(0.0, sum2[c] / n - mean * mean) / (n - 1)));
    }
    return r;
}

void expectSameMean(const MeanAndError& a, const MeanAndError& b, const std::string& what) {
    for (int c = 0; c < 3; ++c) {
        const double se = std::hypot(a.standardError[c], b.standardError[c]);
        EXPECT_NEAR(a.mean[c], b.mean[c], 4.5 * se + 1e-12) << what << " channel " << c;
    }
}

TEST(StochasticLightcuts, EachQueryMatchesPlainVrlsInExpectation) {
    int compared = 0;
    for (const MediumCase& m : kMedia) {
        const auto scene = sphereInBoxedMedium(m);
        Rng rng(21, uint64_t(&m - kMedia));
        const LightTree tree = LightTree::build(randomVrls(rng, 300), LightTreeSettings{64, 5});
        const VrlEstimator estimator(*scene, 1);
        const VrlSurfaceEstimator surfaceEstimator(*scene, 1);
        CutSettings settings;
        settings.stochasticCutSize = 8;
        const StochasticLightcutsEstimator stochastic(*scene, tree, estimator, surfaceEstimator, settings);
        for (int q = 0; q < 8; ++q) {
            const CameraSegment segment = randomSegment(tree, rng, q % 4);
            CutStatistics statistics;
            const MeanAndError cut = meanOf(4000, [&](int i) {
                Rng r(1000 + q, uint64_t(i));
                return stochastic.estimate(segment, r, statistics);
            });
            const MeanAndError plain = meanOf(64, [&](int i) {
                Rgb sum(0.0f);
                for (size_t k = 0; k < tree.vrls().size(); ++k) {
                    Rng r(2000 + q, uint64_t(i) * 4096 + k);
                    sum += estimator.contribution(tree.vrls()[k], segment, r);
                }
                return sum;
            });
            EXPECT_EQ(statistics.evaluated, 4000u * 8u);
            expectSameMean(cut, plain, std::string(m.name) + " segment " + std::to_string(q));
            if (q == 0)
                std::printf("%s segment 0: stochastic %.5g +- %.2g, plain %.5g +- %.2g (green)\n", m.name, cut.mean.y,
                            cut.standardError.y, plain.mean.y, plain.standardError.y);
            ++compared;

            const auto x = randomSurfacePoint(*scene, rng);
            if (!x) continue;
            const MeanAndError cutS = meanOf(4000, [&](int i) {
                Rng r(3000 + q, uint64_t(i));
                return stochastic.estimate(*x, r, statistics);
            });
            const MeanAndError plainS = meanOf(64, [&](int i) {
                Rgb sum(0.0f);
                for (size_t k = 0; k < tree.vrls().size(); ++k) {
                    Rng r(4000 + q, uint64_t(i) * 4096 + k);
                    sum += surfaceEstimator.contribution(tree.vrls()[k], *x, r);
                }
                return sum;
            });
            expectSameMean(cutS, plainS, std::string(m.name) + " surface point " + std::to_string(q));
            ++compared;
        }
    }
    std::printf("%d queries compared\n", compared);
    EXPECT_GE(compared, 40);
}

// --- The whole image: one VRL set, 64 camera seeds --------------------------

// A quarter of the camera seeds in the sanitizer build (test_workload.h).
constexpr int kSeeds = 64 / test::kSanitizedWorkDivisor, kPlainSeeds = 8;
constexpr int kBlock = 8;

std::vector<Rgb> blockMeans(const Image& image) {
    std::vector<Rgb> means;
    for (int by = 0; by < image.height(); by += kBlock)
        for (int bx = 0; bx < image.width(); bx += kBlock) {
            Rgb sum(0.0f);
            for (int y = by; y < std::min(by + kBlock, image.height()); ++y)
                for (int x = bx; x < std::min(bx + kBlock, image.width()); ++x) sum += image.at(x, y);
            means.push_back(sum / float(kBlock * kBlock));
        }
    Rgb all(0.0f);
    for (const auto& p : image.pixels()) all += p;
    means.push_back(all / float(image.pixelCount()));
    return means;
}

// Image and block means over the seeds, with their standard errors, of `method`
// over the VRLs of `lights`.
std::vector<MeanAndError> overSeeds(const Scene& scene, RenderSettings settings, const RenderLights& lights,
                                    int seeds) {
    std::vector<std::vector<Rgb>> runs;
    const TileRect whole{0, 0, scene.camera().width(), scene.camera().height()};
    for (int s = 0; s < seeds; ++s) {
        settings.seed = uint64_t(100 + s);
        const TileShader shader(scene, settings, lights);
        runs.push_back(blockMeans(shader.renderTile(whole).layers[0]));
    }
    std::vector<MeanAndError> out;
    for (size_t i = 0; i < runs[0].size(); ++i)
        out.push_back(meanOf(seeds, [&](int s) { return runs[size_t(s)][i]; }));
    return out;
}

void expectImagesAgree(const std::vector<MeanAndError>& a, const std::vector<MeanAndError>& b, const std::string& what) {
    for (size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double se = std::hypot(a[i].standardError[c], b[i].standardError[c]);
            EXPECT_NEAR(a[i].mean[c], b[i].mean[c], 5.0 * se + 1e-7)
                << what << (i + 1 == a.size() ? ": image" : ": block ") << i << " channel " << c;
        }
    const MeanAndError& image = a.back();
    std::printf("%s: image mean (green) stochastic %.5f +- %.5f, plain %.5f +- %.5f\n", what.c_str(), image.mean.y,
                image.standardError.y, b.back().mean.y, b.back().standardError.y);
    EXPECT_GT(b.back().mean.y, 0.0f) << what;
    EXPECT_LT(image.standardError.y, 0.03f * test::kSanitizedNoiseFactor * b.back().mean.y) << what << ": too noisy to mean much";
}

void expectStochasticMatchesPlain(const Scene& scene, const std::string& transports, const std::string& what) {
    RenderSettings settings;
    settings.method = RenderMethod::VrlStochastic;
    settings.transports = TransportSelection::parse(transports);
    settings.vrlCount = 2000;
    settings.seed = 7;
    settings.samplesPerPixel = 4;
    settings.cut.stochasticCutSize = 16;
    const RenderLights tree = prepareLights(scene, settings);
    ASSERT_FALSE(tree.tree.empty());
    RenderLights plainLights;
    plainLights.vrls.vrls = tree.tree.vrls();
    RenderSettings plain = settings;
    plain.method = RenderMethod::Vrl;
    plain.samplesPerPixel = 1;
    expectImagesAgree(overSeeds(scene, settings, tree, kSeeds), overSeeds(scene, plain, plainLights, kPlainSeeds), what);
}

TEST(StochasticLightcuts, ImageMatchesPlainVrlsOverTheSameVrlSetWithoutSurfaces) {
    for (const MediumCase& m : kMedia) {
        const auto scene = Scene::build(test::mediumOnlyCube(m.sigmaS, m.sigmaA, m.g));
        expectStochasticMatchesPlain(*scene, "multiple", std::string(m.name) + " medium cube (d)");
    }
}

TEST(StochasticLightcuts, ImageMatchesPlainVrlsOverTheSameVrlSetWithSurfaces) {
    for (const MediumCase& m : kMedia) {
        const auto scene = Scene::build(test::litRoomWithOccluder(m.sigmaS * 0.5f, m.sigmaA * 0.5f, m.g));
        expectStochasticMatchesPlain(*scene, "medium-surface,multiple", std::string(m.name) + " lit room (c)+(d)");
    }
}

}  // namespace
}  // namespace vrl
