// Stiff cases, group "tree" (stiff_cases.h): light trees of one VRL, of
// identical VRLs, of collinear VRLs, of fluxes from 1e-30 to 1e30 and of
// 10^6 / 10^7 VRLs (CaseOptions::manyVrls): tree totals, bounds, threshold-0
// cuts against plain VRLs, and the VPL side of each tree.
#include "tests/render/stiff/stiff_case_groups.h"
#include "tests/render/stiff/stiff_case_support.h"

#include "render/lightcuts/cuts/vpl_lightcuts_estimator.h"
#include "render/lightcuts/cuts/lightcuts_estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace vrl::stiff {
namespace {

// VPL side of a tree case: the same positions as points. Bound >= the representative's
// term (isotropic convex medium) at every inner node for each point; gather at
// threshold 0 against the brute-force sum (1e-4, as vpl_lightcuts_test).
void checkVplTree(CaseResult& r, const Scene& scene, std::vector<Vrl> points, const std::vector<Vec3>& xs) {
    for (Vrl& p : points) p.length = 0.0f;
    const LightTree tree = LightTree::build(points, LightTreeSettings{2048, 3, true});
    CutSettings exact;
    exact.errorThreshold = 0.0f;
    exact.maxCutSize = std::numeric_limits<uint32_t>::max();
    const VplLightcutsEstimator estimator(scene, tree, exact);
    const VplLightcutsEstimator approximate(scene, tree, CutSettings{});
    double worst = 0.0;
    Rng rng(77, 0);
    for (const Vec3& x : xs) {
        const Vec3 toCamera = toF(uniformDirection(rng));
        for (size_t n = points.size(); n < tree.nodes().size(); ++n) {
            const LightTreeNode& node = tree.nodes()[n];
            const Rgb b = estimator.bound(int32_t(n), x, 0);
            if (!isFinite(b)) continue;
            const Rgb e = estimator.vplContribution(tree.vrls()[node.representative], node.clusterFlux, x, toCamera, 0);
            checkValue(r, e);
            ++r.boundChecks;
            if (e.x > b.x || e.y > b.y || e.z > b.z) ++r.boundViolations;
        }
        V3d brute(0.0);
        for (const Vrl& v : tree.vrls()) brute += toD(estimator.vplContribution(v, v.flux, x, toCamera, 0));
        CutStatistics statistics;
        const Rgb gathered = estimator.gather(x, toCamera, 0, statistics);
        const Rgb approx = approximate.gather(x, toCamera, 0, statistics);
        checkValue(r, gathered);
        checkValue(r, approx);
        const double scale = std::max({brute.x, brute.y, brute.z});
        for (int c = 0; c < 3; ++c)
            worst = std::max(worst, scale > 0.0 ? std::abs(gathered[c] - brute[c]) / scale : std::abs(double(gathered[c])));
    }
    compare(r, "VPL Lightcuts gather at threshold 0 vs brute force, rel. diff", worst,
            accumulationTolerance(points.size()));
}

void oneVrlCase(CaseResult& r) {
    r.description = "a light tree of one VRL (and one VPL): the root is the leaf; Lightcuts at thresholds 0 and "
                    "0.02 equal plain VRLs bit for bit on 16 segments; VPL gather = brute force";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const Vrl v = makeVrl(V3d(0.2, 0.1, 0.5), V3d(1, 1, 0), 0.7, Rgb(1.0f, 2.0f, 3.0f));
    const LightTree tree = LightTree::build({v});
    require(r, tree.root() == 0 && tree.nodes().size() == 1 && tree.nodes()[0].isLeaf(), "one VRL: root is the leaf");
    const VrlEstimator estimator(*scene, 1);
    const LightcutsEstimator cut(*scene, tree, estimator, CutSettings{});
    Rng rng(2100, 0);
    int mismatches = 0;
    std::vector<CameraSegment> segments;
    std::vector<Vec3> xs;
    for (int k = 0; k < 16; ++k) {
        segments.push_back(makeSegment(uniformInCube(rng, 1.0), uniformDirection(rng), 3.0));
        xs.push_back(toF(uniformInCube(rng, 1.0)));
        Rng a = vrlStream(k, 0);
        const Rgb plain = estimator.contribution(v, segments.back(), a);
        CutStatistics statistics;
        const Rgb c = cut.estimate(segments.back(), k, statistics);
        checkValue(r, c);
        if (!(c == plain)) ++mismatches;
    }
    compare(r, "segments where the one-VRL cut differs from the plain estimate", mismatches, 0.0);
    checkCutAgainstPlain(r, *scene, tree, segments, 2101, "one VRL", 0.0);
    checkVplTree(r, *scene, {v}, xs);
}

// Shared by the identical / collinear cases: tree invariants (counts, flux x length conserved).
void checkTreeTotals(CaseResult& r, const LightTree& tree, const std::vector<Vrl>& vrls, bool points = false) {
    require(r, tree.nodes().size() == 2 * vrls.size() - 1, "a tree of N VRLs has 2N - 1 nodes");
    const LightTreeNode& root = tree.nodes()[tree.root()];
    require(r, root.vrlCount == vrls.size(), "the root holds every VRL");
    V3d total(0.0);
    for (const Vrl& v : vrls) total += toD(v.flux) * (points ? 1.0 : double(v.length));
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, relativeDifference(root.fluxLength[c], total[c]));
    for (const LightTreeNode& node : tree.nodes()) {
        checkValue(r, node.fluxLength);
        checkValue(r, node.clusterFlux);
    }
    // Float sums over the tree: ~log2(N) roundings of 6e-8 each.
    compare(r, "root flux x length vs the double-precision sum, rel. diff", worst, 1e-5);
}

void identicalVrlsCase(CaseResult& r) {
    r.description = "10^4 identical VRLs: tree build, counts and flux; bounds; threshold-0 cut = plain on 4 "
                    "segments; the default cut (one representative for all) agrees with plain VRLs in "
                    "expectation (64 segments' streams)";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const std::vector<Vrl> vrls(10'000, makeVrl(V3d(0.3, -0.2, 0.8), V3d(1, 0.5, 0.2), 0.6, Rgb(1e-4f)));
    const auto start = std::chrono::steady_clock::now();
    const LightTree tree = LightTree::build(vrls);
    note(r, format("build %.3f s", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
    checkTreeTotals(r, tree, vrls);
    const std::vector<CameraSegment> segments = {zSegment(), makeSegment(V3d(-1, 0, 0), V3d(1, 0.1, 0.1), 3.0),
                                                 makeSegment(V3d(0.3, -0.2, -1), kZ3, 4.0),  // meets the VRLs' origin
                                                 zSegment(1e30)};
    checkClusterBounds(r, *scene, tree, {segments[0], segments[1]}, 4, 2200);
    checkCutAgainstPlain(r, *scene, tree, segments, 2201, "identical");
    // Default threshold: the root's estimate is one sample carrying all the flux; its
    // mean over streams must match the plain mean (z over 256 streams).
    const VrlEstimator estimator(*scene, 1);
    const LightcutsEstimator cut(*scene, tree, estimator, CutSettings{});
    double sum = 0, sum2 = 0, plainSum = 0, plainSum2 = 0;
    constexpr int kStreams = 256;
    for (int k = 0; k < kStreams; ++k) {
        CutStatistics statistics;
        const double c = cut.estimate(segments[1], 5000 + k, statistics).x;
        sum += c, sum2 += c * c;
        double p = 0;
        for (uint32_t j = 0; j < 200; ++j) {  // 200 of the identical VRLs, scaled: the plain estimator's mean
            Rng rng = vrlStream(9000 + k, j);
            p += estimator.contribution(vrls[j], segments[1], rng).x;
        }
        p *= 10'000.0 / 200.0;
        plainSum += p, plainSum2 += p * p;
    }
    const double m = sum / kStreams, pm = plainSum / kStreams;
    const double se = std::sqrt((sum2 / kStreams - m * m + plainSum2 / kStreams - pm * pm) / (kStreams - 1));
    compare(r, format("default cut vs plain over %d streams: z (%.5g vs %.5g)", kStreams, m, pm), zScore(m, se, pm, 0.0),
            kZ);
    std::vector<Vec3> xs = {Vec3(0.3f, -0.2f, 0.8f), Vec3(0.0f), Vec3(1.0f, 0.5f, 0.5f)};
    checkVplTree(r, *scene, vrls, xs);
}

void collinearVrlsCase(CaseResult& r) {
    r.description = "10^4 VRLs on one line (overlapping, both directions, lengths 1e-7 .. 1): tree counts and flux; "
                    "a camera ray on that line: every node crossed, cut = all leaves = plain even at threshold "
                    "0.02; a parallel ray 0.1 away: bounds, threshold-0 cut";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    Rng rng(2300, 0);
    std::vector<Vrl> vrls;
    const V3d dir = V3d(1, 2, 2).normalized(), origin(0.1, -0.3, 0.2);
    for (int k = 0; k < 10'000; ++k) {
        const double length = std::pow(10.0, -7.0 * rng.nextDouble());
        const double sign = rng.next() < 0.5f ? 1.0 : -1.0;
        vrls.push_back(makeVrl(origin + dir * (4.0 * rng.nextDouble() - 2.0), dir * sign, length,
                               Rgb(float(1e-4 * rng.nextDouble()))));
    }
    const LightTree tree = LightTree::build(vrls);
    checkTreeTotals(r, tree, vrls);
    const CameraSegment onLine = makeSegment(origin - dir * 3.0, dir, 2.0);
    const VrlEstimator estimator(*scene, 1);
    const LightcutsEstimator cut(*scene, tree, estimator, CutSettings{});
    CutStatistics statistics;
    const Rgb c = cut.estimate(onLine, 11, statistics);
    checkValue(r, c);
    V3d plain(0.0);
    for (uint32_t k = 0; k < vrls.size(); ++k) {
        Rng s = vrlStream(11, k);
        const Rgb e = estimator.contribution(tree.vrls()[k], onLine, s);
        checkValue(r, e);
        plain += toD(e);
    }
    compare(r, "camera on the line, threshold 0.02: cut vs plain, rel. diff", relativeDifference(c.x, plain.x), 1e-4);
    require(r, statistics.cutSize == vrls.size(), format("camera on the line: cut %u, expected every leaf", statistics.cutSize));
    require(r, statistics.intersected == vrls.size() - 1, "camera on the line: every inner node crossed");
    const CameraSegment parallel = makeSegment(origin - dir * 3.0 + V3d(0.1 * 2.0 / 3.0, -0.1 * 2.0 / 3.0, 0.1 / 3.0), dir, 6.0);
    checkCutAgainstPlain(r, *scene, tree, {parallel, onLine}, 2301, "collinear");
    // Bounds along the parallel ray: the small tree of the first 200 VRLs (every node, 4 samples).
    const LightTree small = LightTree::build(std::vector<Vrl>(vrls.begin(), vrls.begin() + 200));
    checkClusterBounds(r, *scene, small, {parallel}, 4, 2302);
    std::vector<Vec3> xs = {toF(origin + V3d(0, 0, 0.05)), toF(origin + dir * 0.5), toF(origin + V3d(1, 0, 0))};
    checkVplTree(r, *scene, vrls, xs);
}

void fluxRangeCase(CaseResult& r) {
    r.description = "4000 VRLs with fluxes log-uniform in 1e-30 .. 1e30 (independently per channel): tree flux "
                    "totals; bounds; threshold-0 cut = plain; default cut finite; VPL gather = brute force";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    Rng rng(2400, 0);
    std::vector<Vrl> vrls;
    for (int k = 0; k < 4000; ++k) {
        Rgb flux;
        for (int c = 0; c < 3; ++c) flux[c] = float(std::pow(10.0, -30.0 + 60.0 * rng.nextDouble()));
        vrls.push_back(makeVrl(uniformInCube(rng, 1.0), uniformDirection(rng), 0.05 + 0.5 * rng.nextDouble(), flux));
    }
    const LightTree tree = LightTree::build(vrls);
    checkTreeTotals(r, tree, vrls);
    std::vector<CameraSegment> segments;
    std::vector<Vec3> xs;
    for (int k = 0; k < 4; ++k) {
        segments.push_back(makeSegment(uniformInCube(rng, 1.0), uniformDirection(rng), 3.0));
        xs.push_back(toF(uniformInCube(rng, 1.0)));
    }
    checkCutAgainstPlain(r, *scene, tree, segments, 2401, "flux range");
    const LightTree small = LightTree::build(std::vector<Vrl>(vrls.begin(), vrls.begin() + 300));
    checkClusterBounds(r, *scene, small, segments, 4, 2402);
    checkVplTree(r, *scene, vrls, xs);
}

void manyVrlsCase(CaseResult& r, const CaseOptions& options) {
    const uint64_t n = options.manyVrls;
    r.description = format("%.0e random VRLs in [-1,1]^3 (unbounded isotropic medium): build time and memory; "
                           "counts and flux; default cut on 8 segments: finite, >= 0, bound never exceeded, "
                           "within 5 x threshold of plain VRLs on average (2 segments)",
                           double(n));
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    std::vector<Vrl> vrls(n);
    for (uint64_t k = 0; k < n; ++k) {
        Rng rng(2500, k);
        const V3d o = uniformInCube(rng, 1.0);
        const V3d d = uniformDirection(rng);
        const double length = -0.2 * std::log1p(-rng.nextDouble());
        vrls[k] = makeVrl(o, d, length, Rgb(float(1.0 / double(n)) * (0.5f + rng.next())));
    }
    const size_t inputBytes = vrls.capacity() * sizeof(Vrl);
    const auto start = std::chrono::steady_clock::now();
    const LightTree tree = LightTree::build(std::move(vrls));
    const double buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    note(r, format("build %.2f s, tree.memoryBytes() %.1f MiB (VRLs %.1f MiB + nodes %.1f MiB)", buildSeconds,
                   tree.memoryBytes() / 1048576.0, inputBytes / 1048576.0,
                   (tree.memoryBytes() - inputBytes) / 1048576.0));
    checkTreeTotals(r, tree, tree.vrls());
    const VrlEstimator estimator(*scene, 1);
    const LightcutsEstimator cut(*scene, tree, estimator, CutSettings{});
    Rng rng(2501, 0);
    double meanCut = 0.0, errorSum = 0.0;
    int plainSegments = 0;
    for (int k = 0; k < 8; ++k) {
        const CameraSegment seg = makeSegment(uniformInCube(rng, 1.5), uniformDirection(rng), 3.0);
        CutStatistics statistics;
        const auto t0 = std::chrono::steady_clock::now();
        const Rgb c = cut.estimate(seg, 100 + k, statistics);
        const double cutSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        checkValue(r, c);
        r.boundChecks += statistics.boundedEstimates;
        r.boundViolations += statistics.boundExceeded;
        meanCut += statistics.cutSize / 8.0;
        if (k < 2) {
            double plain = 0.0;
            for (uint32_t j = 0; j < tree.vrls().size(); ++j) {
                Rng s = vrlStream(100 + k, j);
                plain += estimator.contribution(tree.vrls()[j], seg, s).x;
            }
            errorSum += relativeDifference(c.x, plain);
            ++plainSegments;
            note(r, format("segment %d: cut %u nodes in %.2f ms, rel. diff to plain %.3g", k, statistics.cutSize,
                           1e3 * cutSeconds, relativeDifference(c.x, plain)));
        }
    }
    note(r, format("mean cut size %.0f", meanCut));
    compare(r, "mean rel. diff of the default cut (threshold 0.02) vs plain VRLs", errorSum / plainSegments, 0.1);
}

}  // namespace

std::vector<StiffCase> treeCases() {
    std::vector<StiffCase> cases;
    const auto add = [&cases](const std::string& group, const std::string& name, std::function<void(CaseResult&)> f) {
        cases.push_back(makeCase(group, name, std::move(f)));
    };
    add("tree", "one VRL", oneVrlCase);
    add("tree", "identical VRLs", identicalVrlsCase);
    add("tree", "collinear VRLs", collinearVrlsCase);
    cases.push_back({"tree", "many VRLs", manyVrlsCase, ""});
    add("tree", "fluxes 1e-30 .. 1e30", fluxRangeCase);
    return cases;
}

}  // namespace vrl::stiff
