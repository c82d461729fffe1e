// stochastic_bench: stochastic VRL Lightcuts (vrl-stochastic) against plain VRLs
// and deterministic VRL Lightcuts, for part (d) (or (c) with --part
// medium-surface), on one scene at several VRL counts N.
//
// The error is the relative RMSE (luminance, image_metrics.h) against the
// converged part of the *same* VRL set: the mean of `--reference-runs` plain-VRL
// renders with independent (u, v) samples. That is what every method here
// estimates (a cut cannot remove the error of the VRL set itself, which all
// three share). Plain VRLs (one (u, v) sample per VRL, another seed than the
// reference's) and Lightcuts at --error are rendered once each; vrl-stochastic
// at 1, 2, 4, ... samples per pixel until it has run --time-factor times the
// Lightcuts time. Per N it prints each method's time and error, and:
//   st_eq_plain: the time vrl-stochastic needs to reach plain's error (the
//     Monte Carlo rate error ~ t^-1/2 from its last measured point; '*' when
//     extrapolated past the measured range), and plain's time over it;
//   st_at_lc: the error of vrl-stochastic at the Lightcuts time (interpolated
//     on the same rate between the measured points) against the Lightcuts error;
//   st_eq_lc: the time vrl-stochastic needs to reach the Lightcuts error, and
//     the Lightcuts time over it;
//   #Eval (VRL estimates) and importances per pixel and sample.
//
// --truth measures against the *true* part instead (what a user wants): the
// reference is the mean over --truth-sets independent VRL sets of
// --truth-vrls VRLs, each shaded by vrl-stochastic at --truth-spp (unbiased for
// the transport of its set, so the mean converges to the true part); its own
// noise is estimated from two independent halves and printed beside it. Every
// method then pays for its VRL set's error: plain VRLs and Lightcuts use one
// set of N; vrl-stochastic runs with P = 1, 2, 4, ... fresh sets of N (each
// traced and built inside the measured time) at 1, 2, 4, ... samples per pixel
// per set, the image being the mean over the sets (what `vrl render --vrl-sets P`
// does). Times there include light tracing and the tree build. No
// extrapolation: the best measured point at or under each comparison time.
// Timings are wall-clock, one run each, on whatever cores TBB gets: compare
// ratios within one run, not seconds.
#include "bench/bench_lights.h"
#include "bench/bench_scene_arguments.h"
#include "bench/stochastic_ceiling.h"
#include "render/core/timing.h"
#include "render/description/scene_description.h"
#include "render/image/image_metrics.h"
#include "render/integrators/transport_integrator.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/cuts/stochastic_cut.h"
#include "render/lightcuts/cuts/vrl_importance.h"
#include "render/scene/scene.h"
#include "render/scene_io/medium_fill.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "render/vrl/camera_segment.h"
#include "render/vrl/light_tracer.h"
#include "render/vrl/vrl_estimator.h"
#include "util/command_line.h"

#include <CLI/CLI.hpp>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <tuple>

using namespace vrl;

namespace {

enum class Method { Plain, Lightcuts, Stochastic };

struct Shading {
    Image image;
    double seconds = 0.0;
    double evaluated = 0.0, importances = 0.0;  // per shaded pixel and sample
};

// The part on every `stride`-th pixel in x and y (the others stay black), with
// `spp` samples per pixel (only vrl-stochastic draws more than one).
Shading shade(const Scene& scene, const VrlSet& vrls, const LightTree& tree, Method method, float error, int cutSize,
              int spp, int stride, uint64_t seed, bool surfacePart, int vrlSamples = 1) {
    TransportIntegratorSettings settings;
    settings.vrlSamples = vrlSamples;
    settings.transports = TransportSelection::parse(surfacePart ? "medium-surface" : "multiple");
    settings.cut.errorThreshold = error;
    settings.cut.stochasticCutSize = uint32_t(cutSize);
    if (method == Method::Stochastic)
        settings.estimators = {MediumGathererKind::StochasticVrlCut, SurfaceGathererKind::StochasticVrlCut};
    const TransportIntegrator integrator(scene, vrls, settings, method == Method::Plain ? nullptr : &tree);
    const PerspectiveCamera& camera = scene.camera();
    Shading out;
    out.image = Image(camera.width(), camera.height());
    std::atomic<uint64_t> evaluated{0}, importances{0}, pixels{0};
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(0, (camera.height() + stride - 1) / stride, [&](int row) {
        const int y = row * stride;
        for (int x = 0; x < camera.width(); x += stride) {
            Rng rng(seed, uint64_t(y) * camera.width() + x);
            CutStatistics stats;
            Rgb sum(0.0f);
            for (int s = 0; s < spp; ++s) {
                const auto parts = integrator.virtualLightParts(camera.generateRay(x + 0.5f, y + 0.5f), rng, &stats, &stats);
                sum += surfacePart ? parts.mediumSurface : parts.multiple;
            }
            out.image.at(x, y) = sum / float(spp);
            evaluated += stats.evaluated, importances += stats.importanceEvaluations, ++pixels;
        }
    });
    out.seconds = secondsSince(start);
    const double samples = double(pixels.load()) * spp;
    out.evaluated = double(evaluated.load()) / samples;
    out.importances = double(importances.load()) / samples;
    return out;
}

// --ceiling M: the ceiling of any stochastic cut's saving over plain VRLs
// (stochastic_ceiling.h), and where vrl-stochastic's K-node cut stands under it,
// from the moments of every VRL's one-sample estimate on each shaded pixel's camera
// segments, estimated from M independent (u, v) samples. Each pixel is weighted by
// the reference's luminance, as relRMSE weights it. Pixels whose camera path takes
// a specular bounce are left out (a glass bounce is a random choice, which the
// ceiling does not cover), and so are segments in media that do not scatter.
// The sample deviations' square roots are biased low, mostly in the ceilings'
// denominators: that raises the printed ceilings (the safe side for a bound).
struct Ceiling {
    double ceiling = 0.0;         // any cut, estimates spread over segments at will
    double uniformCeiling = 0.0;  // the same K M on every segment (vrl-stochastic)
    // vrl-stochastic's K-node cut on the same terms as uniformCeiling: with its own
    // descents (predicted from the moments), ideal descents under the same nodes
    // (probabilities fitted to the same samples: optimistic), and each node drawing
    // its VRLs by their own leaf importances.
    double cutGain = 0.0, idealGain = 0.0, leafGain = 0.0;
    double plainEstimates = 0.0;  // N x scattering camera segments, per pixel counted
    double leftOut = 0.0;         // fraction of the shaded pixels left out (specular camera paths)
    double seconds = 0.0;
};

Ceiling stochasticCeiling(const Scene& scene, const VrlSet& vrls, const LightTree& tree, const Image& reference,
                          int samples, int stride, uint32_t cutSize) {
    const VrlEstimator estimator(scene, 1);
    const VrlImportance importance(scene, tree);
    const PerspectiveCamera& camera = scene.camera();
    const int maxDepth = TransportIntegratorSettings{}.maxDepth;  // as shade() renders
    const size_t n = vrls.vrls.size();
    std::vector<VrlEstimator::Query> queries(n);
    for (size_t i = 0; i < n; ++i) queries[i] = {&vrls.vrls[i], vrls.vrls[i].flux, uint32_t(i)};
    struct Sums {
        bench::CeilingSums ceiling;
        double cut = 0.0, ideal = 0.0, leaf = 0.0;  // sum w K V of the cut, three ways
        uint64_t pixels = 0, leftOut = 0;
    };
    std::mutex mutex;
    Sums total;
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(0, (camera.height() + stride - 1) / stride, [&](int row) {
        const int y = row * stride;
        std::vector<Rgb> out(n);
        std::vector<double> sum(n), squares(n);
        std::vector<bench::EstimateMoments> moments(n), leaves;
        std::vector<double> descent, own;
        std::vector<LeafDescent> stack;
        Sums rowSums;
        for (int x = 0; x < camera.width(); x += stride) {
            const uint64_t pixelIndex = uint64_t(y) * camera.width() + x;
            Rng rng(1, pixelIndex);
            const auto segments =
                cameraSegments(scene, camera.generateRay(x + 0.5f, y + 0.5f), scene.cameraMedium(), &rng, maxDepth);
            if (std::any_of(segments.begin(), segments.end(), [](const CameraSegment& g) { return g.specularBefore > 0; })) {
                ++rowSums.leftOut;
                continue;
            }
            ++rowSums.pixels;
            const double r = luminance(reference.at(x, y));
            const double weight = 1.0 / (r * r + kMetricEpsilon);
            for (size_t g = 0; g < segments.size(); ++g) {
                if (segments[g].medium < 0 || scene.media()[size_t(segments[g].medium)].isNonScattering()) continue;
                std::fill(sum.begin(), sum.end(), 0.0);
                std::fill(squares.begin(), squares.end(), 0.0);
                for (int j = 0; j < samples; ++j) {
                    const uint64_t key = Rng::combine(Rng::combine(pixelIndex, g), uint64_t(j));
                    estimator.contributions(queries.data(), n, segments[g], key, out.data());
                    for (size_t i = 0; i < n; ++i) {
                        const double l = luminance(out[i]);
                        sum[i] += l, squares[i] += l * l;
                    }
                }
                for (size_t i = 0; i < n; ++i) moments[i] = {sum[i] / samples, squares[i] / samples};
                rowSums.ceiling.add(moments, weight);
                // vrl-stochastic's cut for this segment; per cut node, its VRLs' descent
                // probabilities and their own importances (from their parents' pairs).
                const VrlImportance::SegmentQuery query = importance.prepare(segments[g]);
                const auto childrenOf = [&](int32_t node) { return importance.children(node, query); };
                const std::vector<int32_t> cut = stochasticCut(tree, cutSize, childrenOf);
                const double k = double(cut.size());
                for (const int32_t c : cut) {
                    leaves.clear(), descent.clear(), own.clear();
                    forEachLeafDescent(
                        tree, c, childrenOf,
                        [&](int32_t leaf, double q, double value) {
                            leaves.push_back(moments[size_t(leaf)]), descent.push_back(q), own.push_back(value);
                        },
                        stack);
                    rowSums.cut += weight * k * bench::nodeVariance(leaves, descent);
                    rowSums.ideal += weight * k * bench::idealNodeVariance(leaves);
                    double ownSum = 0.0;
                    for (const double v : own) ownSum += v;
                    for (double& v : own) v = ownSum > 0.0 ? v / ownSum : 0.0;
                    rowSums.leaf += weight * k * bench::nodeVariance(leaves, own);
                }
            }
        }
        const std::lock_guard lock(mutex);
        total.ceiling.add(rowSums.ceiling);
        total.cut += rowSums.cut, total.ideal += rowSums.ideal, total.leaf += rowSums.leaf;
        total.pixels += rowSums.pixels, total.leftOut += rowSums.leftOut;
    });
    const auto gain = [&](double variance) { return variance > 0.0 ? double(n) * total.ceiling.plain / variance : 0.0; };
    Ceiling c;
    c.ceiling = total.ceiling.ceiling(n);
    c.uniformCeiling = total.ceiling.uniformCeiling(n);
    c.cutGain = gain(total.cut), c.idealGain = gain(total.ideal), c.leafGain = gain(total.leaf);
    c.plainEstimates = total.pixels > 0 ? double(n) * total.ceiling.segments / double(total.pixels) : 0.0;
    c.leftOut = total.pixels + total.leftOut > 0 ? double(total.leftOut) / double(total.pixels + total.leftOut) : 0.0;
    c.seconds = secondsSince(start);
    return c;
}

Image mean(const std::vector<Image>& images) {
    if (images.empty()) throw std::invalid_argument("mean of no images");
    Image out(images[0].width(), images[0].height());
    for (const Image& image : images)
        for (int y = 0; y < out.height(); ++y)
            for (int x = 0; x < out.width(); ++x) out.at(x, y) += image.at(x, y) / float(images.size());
    return out;
}

struct LightSet {
    VrlSet vrls;
    LightTree tree;
    double seconds = 0.0;  // tracing and tree build
};

// Set k of N VRLs (its own light-tracing stream) and its tree.
LightSet traceSet(const Scene& scene, int maxDepth, uint64_t n, uint64_t k, bool withTree) {
    const auto start = std::chrono::steady_clock::now();
    LightTracingSettings tracing;
    tracing.targetVrls = n;
    tracing.maxDepth = maxDepth;
    tracing.seed = 0x9e3779b97f4a7c15ULL * (k + 1);
    LightSet set;
    set.vrls = traceVrls(scene, tracing);
    if (withTree) set.tree = LightTree::build(set.vrls.vrls, LightTreeSettings{2048, k, false});
    set.seconds = secondsSince(start);
    return set;
}

struct TruthOptions {
    uint64_t vrls = 1000000;
    int sets = 8, spp = 32, cutSize = 32;
};

void runAgainstTruth(const Scene& scene, int maxDepth, const std::vector<uint64_t>& counts, float error,
                     const std::vector<int>& cutSizes, double timeFactor, int maxSpp, int maxSets,
                     const TruthOptions& truth, bool surfacePart) {
    // The reference: two independent halves of the sets, whose difference gives its noise.
    std::printf("reference: mean of %d sets of %zu VRLs, vrl-stochastic K %d at %d spp each\n", truth.sets,
                size_t(truth.vrls), truth.cutSize, truth.spp);
    std::fflush(stdout);
    std::vector<Image> halves[2];
    const auto referenceStart = std::chrono::steady_clock::now();
    for (int k = 0; k < truth.sets; ++k) {
        const LightSet set = traceSet(scene, maxDepth, truth.vrls, 1000 + uint64_t(k), true);
        halves[k % 2].push_back(shade(scene, set.vrls, set.tree, Method::Stochastic, error, truth.cutSize, truth.spp, 1,
                                      7000 + uint64_t(k), surfacePart)
                                    .image);
    }
    std::vector<Image> all = halves[0];
    all.insert(all.end(), halves[1].begin(), halves[1].end());
    const Image reference = mean(all);
    // Var(mean of all) = Var(half difference) / 4 for equal halves.
    const double referenceNoise = 0.5 * compareImages(mean(halves[0]), mean(halves[1])).relativeRmse;
    std::printf("reference built in %.1f s; its own noise (half the RMSE between its halves, relative): %.5f\n",
                secondsSince(referenceStart), referenceNoise);
    std::printf("errors: relative RMSE against the true part; a method error under 3x the reference noise is marked '~'\n");
    const auto mark = [&](double e) { return e < 3.0 * referenceNoise ? "~" : " "; };
    for (uint64_t n : counts) {
        LightSet set = traceSet(scene, maxDepth, n, 0, true);
        std::printf("\nN = %zu VRLs (trace + tree %.2f s)\n", set.vrls.vrls.size(), set.seconds);
        const Shading plain = shade(scene, set.vrls, set.tree, Method::Plain, error, 1, 1, 1, 1, surfacePart);
        const Shading cuts = shade(scene, set.vrls, set.tree, Method::Lightcuts, error, 1, 1, 1, 1, surfacePart);
        const double plainError = compareImages(reference, plain.image).relativeRmse;
        const double cutsError = compareImages(reference, cuts.image).relativeRmse;
        const double plainTime = plain.seconds + set.seconds, cutsTime = cuts.seconds + set.seconds;
        std::printf("  %-34s %9.3f s  relRMSE %.5f%s\n", "plain VRLs (one set)", plainTime, plainError, mark(plainError));
        std::printf("  %-34s %9.3f s  relRMSE %.5f%s  #Eval %.0f per pixel\n", "VRL Lightcuts (one set)", cutsTime,
                    cutsError, mark(cutsError), cuts.evaluated);
        std::fflush(stdout);
        for (const int cutSize : cutSizes) {
            struct Point {
                int sets, spp;
                double seconds, error;
            };
            std::vector<Point> points;
            for (int p = 1; p <= maxSets; p *= 2) {
                std::vector<LightSet> sets;
                double setup = 0.0;
                for (int k = 0; k < p; ++k) {
                    sets.push_back(k == 0 ? std::move(set) : traceSet(scene, maxDepth, n, uint64_t(k), true));
                    setup += sets.back().seconds;
                }
                for (int spp = 1; spp <= maxSpp; spp *= 2) {
                    std::vector<Image> images;
                    double seconds = setup, evaluated = 0.0;
                    for (int k = 0; k < p; ++k) {
                        const Shading st = shade(scene, sets[size_t(k)].vrls, sets[size_t(k)].tree, Method::Stochastic,
                                                 error, cutSize, spp, 1, 100 + uint64_t(k), surfacePart);
                        images.push_back(st.image);
                        seconds += st.seconds;
                        evaluated += st.evaluated / p;
                    }
                    const double e = compareImages(reference, mean(images)).relativeRmse;
                    points.push_back({p, spp, seconds, e});
                    std::printf("  vrl-stochastic K %4d, %3d sets x %4d spp %9.3f s  relRMSE %.5f%s  #Eval %.1f per pixel and sample\n",
                                cutSize, p, spp, seconds, e, mark(e), evaluated);
                    std::fflush(stdout);
                    if (seconds > timeFactor * cutsTime) break;
                }
                set = std::move(sets[0]);
            }
            // The best measured point within a time, and the fastest one within an error.
            const auto bestWithin = [&](double seconds) -> const Point* {
                const Point* best = nullptr;
                for (const Point& q : points)
                    if (q.seconds <= seconds && (!best || q.error < best->error)) best = &q;
                return best;
            };
            const auto fastestTo = [&](double target) -> const Point* {
                const Point* best = nullptr;
                for (const Point& q : points)
                    if (q.error <= target && (!best || q.seconds < best->seconds)) best = &q;
                return best;
            };
            if (const Point* q = fastestTo(plainError))
                std::printf("  st_eq_plain: %d sets x %d spp reach plain's error in %.3f s: plain VRLs take %.2fx that time\n",
                            q->sets, q->spp, q->seconds, plainTime / q->seconds);
            else
                std::printf("  st_eq_plain: no measured point reaches plain's error\n");
            if (const Point* q = bestWithin(cutsTime))
                std::printf("  st_at_lc:    %d sets x %d spp: relRMSE %.5f in %.3f s <= the Lightcuts time (Lightcuts %.5f): %s\n",
                            q->sets, q->spp, q->error, q->seconds, cutsError,
                            q->error < cutsError ? "stochastic lower" : "Lightcuts lower");
            else
                std::printf("  st_at_lc:    no measured point within the Lightcuts time\n");
            if (const Point* q = fastestTo(cutsError))
                std::printf("  st_eq_lc:    %d sets x %d spp reach the Lightcuts error in %.3f s: VRL Lightcuts take %.2fx that time\n",
                            q->sets, q->spp, q->seconds, cutsTime / q->seconds);
            else
                std::printf("  st_eq_lc:    no measured point reaches the Lightcuts error\n");
        }
    }
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Stochastic VRL Lightcuts against plain VRLs and VRL Lightcuts (part (d), or part (c))"};
    std::string part = "multiple";
    std::string scenePath = "scenes/smoke-room.xml";
    std::vector<uint64_t> counts = {10000, 100000};
    std::string resolution = "64x48";
    float error = 0.02f;
    std::vector<int> cutSizes = {32};
    int referenceRuns = 4;
    double timeFactor = 2.0;
    int maxSpp = 4096;
    int vrlSamples = 1;
    uint64_t strideAbove = 200000;
    int stride = 4;
    std::vector<std::string> defines;
    std::string medium;
    bool againstTruth = false;
    int maxSets = 16;
    int ceilingSamples = 0;
    TruthOptions truth;
    app.add_option("--scene", scenePath, "Scene file (default scenes/smoke-room.xml)");
    app.add_option("-D,--define", defines, "Override a scene <default>: -D name=value (repeatable)");
    app.add_option("--medium", medium, "Fill the scene with a homogeneous medium, as vrl render --medium does "
                                       "(e.g. sigmaS=0.1,sigmaA=0.02)");
    app.add_option("--vrls", counts, "VRL counts to run (default 10000 100000)");
    app.add_option("--resolution", resolution, "Image size WxH (default 64x48)");
    app.add_option("--error", error, "Lightcuts error threshold (default 0.02)");
    app.add_option("--cut-size", cutSizes, "Stochastic cut sizes K to run (default 32)")->check(CLI::Range(1, 1 << 20));
    app.add_option("--reference-runs", referenceRuns, "Plain-VRL renders averaged into the reference (default 4)")
        ->check(CLI::Range(1, 1024));
    app.add_option("--time-factor", timeFactor, "Stochastic runs up to this times the Lightcuts time (default 2)");
    app.add_option("--vrl-samples", vrlSamples, "vrl-stochastic: (u, v) samples per drawn VRL (default 1)")
        ->check(CLI::Range(1, 1024));
    app.add_option("--max-spp", maxSpp, "Most stochastic samples per pixel (default 4096)");
    app.add_option("--stride-above", strideAbove, "Above this N, shade every --stride-th pixel in x and y (default 200000)");
    app.add_option("--stride", stride, "Pixel stride for large N (default 4: 1/16 of the pixels)");
    app.add_option("--part", part, "Transport part: multiple (d, default) or medium-surface (c)")
        ->check(CLI::IsMember({"multiple", "medium-surface"}));
    app.add_flag("--truth", againstTruth, "Measure against the true part (many VRL sets), with fresh sets for vrl-stochastic");
    app.add_option("--max-sets", maxSets, "--truth: most fresh VRL sets for vrl-stochastic (default 16)")->check(CLI::Range(1, 1024));
    app.add_option("--truth-vrls", truth.vrls, "--truth: VRLs per reference set (default 1000000)");
    app.add_option("--truth-sets", truth.sets, "--truth: reference sets, even (default 8)")->check(CLI::Range(2, 4096));
    app.add_option("--truth-cut-size", truth.cutSize, "--truth: K of the reference's vrl-stochastic (default 32)")->check(CLI::Range(1, 1 << 20));
    app.add_option("--truth-spp", truth.spp, "--truth: vrl-stochastic spp per reference set (default 32)")->check(CLI::Range(1, 1 << 20));
    app.add_option("--ceiling", ceilingSamples,
                   "Also print the ceiling of any stochastic cut's speed-up over plain VRLs at equal error, from M "
                   "(u, v) samples per VRL and segment (0: off)")
        ->check(CLI::Range(0, 1024) & !CLI::IsMember({1}));
    CLI11_PARSE(app, argc, argv);
    const bool surfacePart = part == "medium-surface";
    if (ceilingSamples > 0 && (surfacePart || againstTruth)) {
        std::fprintf(stderr, "--ceiling measures part (d) against plain VRLs over one set: not with --part "
                             "medium-surface or --truth\n");
        return 2;
    }

    const auto arguments = bench::parseSceneArguments(defines, resolution);
    if (!arguments) return 2;
    const ParseOptions& parseOptions = arguments->parseOptions;
    const int w = arguments->width, h = arguments->height;
    SceneDescription description = parseMitsubaScene(scenePath, parseOptions);
    if (!medium.empty()) fillWithMedium(description, parseFillMedium(medium));
    description.sensor.width = w;
    description.sensor.height = h;
    const auto scene = Scene::build(description);
    std::printf("scene %s, %dx%d, part %s, Lightcuts error %.3f\n", scenePath.c_str(), w, h,
                surfacePart ? "(c)" : "(d)", error);
    if (againstTruth) {
        runAgainstTruth(*scene, description.integrator.maxDepth, counts, error, cutSizes, timeFactor, maxSpp, maxSets,
                        truth, surfacePart);
        return 0;
    }
    std::printf("errors: relative RMSE against the same VRL set's converged part (mean of %d plain renders)\n",
                referenceRuns);
    for (uint64_t n : counts) {
        const bench::BenchLights lights = bench::traceAndBuild(*scene, n, description.integrator.maxDepth);
        const VrlSet& vrls = lights.vrls;
        const LightTree& tree = lights.tree;
        const int s = n > strideAbove ? stride : 1;
        std::printf("\nN = %zu VRLs%s\n", vrls.vrls.size(), s > 1 ? " (1/16 of the pixels)" : "");
        std::vector<Image> references;
        for (int r = 0; r < referenceRuns; ++r)
            references.push_back(shade(*scene, vrls, tree, Method::Plain, error, 1, 1, s, 1000 + r, surfacePart).image);
        const Image reference = mean(references);
        const Shading plain = shade(*scene, vrls, tree, Method::Plain, error, 1, 1, s, 1, surfacePart);
        const Shading cuts = shade(*scene, vrls, tree, Method::Lightcuts, error, 1, 1, s, 1, surfacePart);
        const double plainError = compareImages(reference, plain.image).relativeRmse;
        const double cutsError = compareImages(reference, cuts.image).relativeRmse;
        std::printf("  %-22s %9.3f s  relRMSE %.5f\n", "plain VRLs", plain.seconds, plainError);
        std::printf("  %-22s %9.3f s  relRMSE %.5f  #Eval %.0f per pixel\n", "VRL Lightcuts", cuts.seconds, cutsError,
                    cuts.evaluated);
        Ceiling ceiling;
        if (ceilingSamples > 0) {
            ceiling = stochasticCeiling(*scene, vrls, tree, reference, ceilingSamples, s, uint32_t(cutSizes.front()));
            std::printf("  ceiling (%d (u, v) samples per VRL, %.1f s, %.1f%% of the pixels left out: specular camera paths):\n"
                        "    any stochastic cut needs >= 1/%.2f of plain's %.0f estimates per pixel for plain's error "
                        "(1/%.2f with the same K x spp on every segment)\n",
                        ceilingSamples, ceiling.seconds, 100.0 * ceiling.leftOut, ceiling.ceiling, ceiling.plainEstimates,
                        ceiling.uniformCeiling);
            std::printf("    the K = %d cut needs 1/%.2f of them with its descents (predicted), 1/%.2f with ideal descents "
                        "under the same nodes, 1/%.2f drawing by the VRLs' own importances\n",
                        cutSizes.front(), ceiling.cutGain, ceiling.idealGain, ceiling.leafGain);
        }
        for (const int cutSize : cutSizes) {
            struct Point {
                int spp;
                double seconds, error, evaluated;
            };
            std::vector<Point> points;
            for (int spp = 1; spp <= maxSpp; spp *= 2) {
                const Shading st =
                    shade(*scene, vrls, tree, Method::Stochastic, error, cutSize, spp, s, 1, surfacePart, vrlSamples);
                const double e = compareImages(reference, st.image).relativeRmse;
                points.push_back({spp, st.seconds, e, st.evaluated});
                std::printf("  vrl-stochastic K %4d %5d spp %9.3f s  relRMSE %.5f  #Eval %.1f, importances %.0f per pixel and sample\n",
                            cutSize, spp, st.seconds, e, st.evaluated, st.importances);
                std::fflush(stdout);
                if (st.seconds > timeFactor * cuts.seconds) break;
            }
            // Time to reach error e on the Monte Carlo rate through the point p: t_p (e_p / e)^2.
            const auto timeFor = [&](double target, bool& extrapolated) {
                for (const Point& p : points)
                    if (p.error <= target) {
                        extrapolated = false;
                        return p.seconds * (p.error / target) * (p.error / target);
                    }
                extrapolated = true;
                const Point& p = points.back();
                return p.seconds * (p.error / target) * (p.error / target);
            };
            const auto errorAt = [&](double seconds) {
                const Point* p = &points.back();
                for (const Point& q : points)
                    if (q.seconds >= seconds) {
                        p = &q;
                        break;
                    }
                return p->error * std::sqrt(p->seconds / seconds);
            };
            bool extrapolated = false;
            const double tPlain = timeFor(plainError, extrapolated);
            std::printf("  st_eq_plain: %.3f s%s to reach plain's error: plain VRLs take %.2fx that time\n", tPlain,
                        extrapolated ? "*" : "", plain.seconds / tPlain);
            std::printf("  st_at_lc:    relRMSE %.5f at the Lightcuts time (Lightcuts %.5f): %s\n", errorAt(cuts.seconds),
                        cutsError, errorAt(cuts.seconds) < cutsError ? "stochastic lower" : "Lightcuts lower");
            const double tCuts = timeFor(cutsError, extrapolated);
            std::printf("  st_eq_lc:    %.3f s%s to reach the Lightcuts error: VRL Lightcuts take %.2fx that time\n", tCuts,
                        extrapolated ? "*" : "", cuts.seconds / tCuts);
            if (ceilingSamples > 0 && ceiling.plainEstimates > 0.0 && points.back().evaluated > 0.0) {
                // At equal error the cut spends >= plain's estimates / ceiling, each at its own
                // measured cost (importances included): plain's time over its time is at most this.
                const Point& last = points.back();
                // Per (u, v) sample: plain takes one per VRL, vrl-stochastic --vrl-samples per drawn VRL.
                const double stochasticPerEstimate = last.seconds / (last.evaluated * last.spp * vrlSamples);
                const double plainPerEstimate = plain.seconds / ceiling.plainEstimates;
                std::printf("  ceiling:     an estimate costs %.2fx plain's, so at equal error this cut is at most %.2fx "
                            "faster than plain VRLs (any importance at this cost, the same spp everywhere)\n",
                            stochasticPerEstimate / plainPerEstimate,
                            ceiling.uniformCeiling * plainPerEstimate / stochasticPerEstimate);
            }
        }
        std::fflush(stdout);
    }
    return 0;
}
