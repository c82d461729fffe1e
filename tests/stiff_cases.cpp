// The stiff-case suite (stiff_cases.h). Conventions used throughout:
//
// * Statistical agreement is a z score: |mean - reference| in standard errors
//   of the mean, after allowing the reference's own relative error (quadrature
//   convergence, float accumulation). Estimator-level cases average 5e4 - 2e5
//   independent samples (the mean is close to normal) and allow kZ = 4.5: a
//   correct estimator fails one of the suite's ~250 such comparisons with
//   probability below 0.2% (two-sided normal tail 6.8e-6 each). Image-level
//   cases average K = 8 independent (or, for paired cases, paired) renders and
//   allow kImageZ = 6: P(|t_7| > 6) = 5.4e-4 per comparison, about 3% over the
//   suite's ~60 independent image comparisons (grey media repeat one comparison
//   in three channels). Where a reference is heavy-tailed (next-event estimation
//   near a point light in a medium), its standard error is an underestimate; the
//   cases say so.
// * Deterministic agreement (threshold-0 Lightcuts against plain VRLs, exact
//   transmittance, analytic bounds) is a relative difference against a
//   float-rounding tolerance stated with each check.
// * Seeds are fixed, so every case is deterministic; the tolerances say how
//   unlikely a failure of a correct implementation would be under other seeds.
#include "tests/stiff_cases.h"

#include "render/cluster_bound.h"
#include "render/cut.h"
#include "render/light_tracer.h"
#include "render/light_tree.h"
#include "render/renderer.h"
#include "render/rng.h"
#include "render/scene.h"
#include "render/vpl_lightcuts.h"
#include "render/vrl_estimator.h"
#include "tests/test_scenes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <exception>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>

namespace vrl::stiff {

const Comparison* CaseResult::worst() const {
    const Comparison* w = nullptr;
    double worstRatio = -1.0;
    for (const Comparison& c : comparisons) {
        const double ratio = c.tolerance > 0.0 ? c.value / c.tolerance : (c.value > 0.0 ? kInfinity : 0.0);
        const double key = std::isnan(ratio) ? kInfinity : ratio;
        if (key > worstRatio) worstRatio = key, w = &c;
    }
    return w;
}

namespace {

using V3d = Imath::V3d;
constexpr double kPiD = 3.14159265358979323846;
constexpr double kInfD = std::numeric_limits<double>::infinity();
constexpr double kZ = 4.5;       // estimator-level z tolerance (see the file comment)
constexpr double kImageZ = 6.0;  // image-level t tolerance over K = 8 runs (see the file comment)

V3d toD(const Vec3& v) { return {v.x, v.y, v.z}; }
Vec3 toF(const V3d& v) { return Vec3(float(v.x), float(v.y), float(v.z)); }

std::string format(const char* f, ...) {
    char buffer[1024];
    va_list args;
    va_start(args, f);
    std::vsnprintf(buffer, sizeof buffer, f, args);
    va_end(args);
    return buffer;
}

// ---- Result helpers ------------------------------------------------------------

void checkValue(CaseResult& r, double v) {
    ++r.valuesChecked;
    if (!std::isfinite(v)) r.finite = false;
    if (!(v >= 0.0) && !std::isnan(v)) r.nonNegative = false;
}
void checkValue(CaseResult& r, const Rgb& c) {
    for (int i = 0; i < 3; ++i) checkValue(r, double(c[i]));
}
void fail(CaseResult& r, const std::string& message) {
    if (r.failures.size() < 20) r.failures.push_back(message);
}
void require(CaseResult& r, bool ok, const std::string& message) {
    if (!ok) fail(r, message);
}
void compare(CaseResult& r, const std::string& label, double value, double tolerance) {
    r.comparisons.push_back({label, value, tolerance});
}
void note(CaseResult& r, const std::string& text) { r.notes += (r.notes.empty() ? "" : "; ") + text; }

// |mean - reference| in standard errors after allowing `allowance` (absolute).
double zScore(double mean, double se, double reference, double allowance) {
    const double excess = std::abs(mean - reference) - allowance;
    if (!(excess > 0.0)) return std::isnan(excess) ? kInfD : 0.0;
    return se > 0.0 ? excess / se : kInfD;
}

// Recursive float summation of n terms: relative error up to about n 2^-24 (with a
// factor 4 of headroom), never below the 1e-4 lightcuts_test uses for images.
double accumulationTolerance(size_t n) { return std::max(1e-4, 4.0 * double(n) * 0x1p-24); }

double relativeDifference(double a, double b) {
    const double scale = std::max(std::abs(a), std::abs(b));
    return scale > 0.0 ? std::abs(a - b) / scale : (a == b ? 0.0 : kInfD);
}

// ---- Scenes ----------------------------------------------------------------------

MediumDescription mediumDescription(const Rgb& sigmaS, const Rgb& sigmaA, float g) {
    MediumDescription m;
    m.id = "stiff";
    m.sigmaS = sigmaS;
    m.sigmaA = sigmaA;
    if (g != 0.0f) m.phase = {PhaseDescription::Kind::HenyeyGreenstein, g};
    return m;
}

// One unbounded medium, no shapes (visibility 1, convex): the estimator-level cases.
std::unique_ptr<Scene> unboundedScene(const Rgb& sigmaS, const Rgb& sigmaA, float g) {
    return Scene::build(test::pointLightInInfiniteMedium(Rgb(1.0f), Vec3(0.0f), sigmaS, sigmaA, g));
}

// ---- Reference quadrature (double precision, independent of vrl_estimator.cpp) ----
//   L = Tb Phi sigma_s^2 int_0^S int_0^t fV(d, n) fU(n, -w) e^{-sigma_t (u + |x_u - x_v|)} / |x_u - x_v|^2 dv du,
// with u = delta + h tan(theta) (du / w^2 = dtheta / h) and v = v0 + h0 sinh(alpha) / sinT
// around the lines' closest approach (dv / h = dalpha / sinT): smooth integrands
// unless the lines cross inside both segments.

struct MediumParams {
    V3d sigmaS, sigmaT;
    double g = 0.0;
};
MediumParams paramsOf(const HomogeneousMedium& m) { return {toD(m.sigmaS()), toD(m.sigmaT()), m.phase().g()}; }

double hg(double g, double cosine) {
    if (g == 0.0) return 1.0 / (4.0 * kPiD);
    const double denom = 1.0 + g * g - 2.0 * g * cosine;
    return (1.0 - g * g) / (4.0 * kPiD * denom * std::sqrt(denom));
}
V3d expD(const V3d& v) { return {std::exp(v.x), std::exp(v.y), std::exp(v.z)}; }

template <class F>
V3d gaussLegendre(F f, double lo, double hi, int panels) {
    static constexpr double x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
    static constexpr double w[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
    V3d sum(0.0);
    const double width = (hi - lo) / panels;
    for (int p = 0; p < panels; ++p) {
        const double mid = lo + (p + 0.5) * width, half = 0.5 * width;
        for (int i = 0; i < 4; ++i) sum += (f(mid - half * x[i]) + f(mid + half * x[i])) * (w[i] * half);
    }
    return sum;
}

V3d quadrature(const Vrl& vrl, const CameraSegment& seg, const MediumParams& m, int panels) {
    const V3d o = toD(seg.origin), w = toD(seg.direction), a = toD(vrl.origin), d = toD(vrl.direction);
    const double s = seg.length, t = vrl.length;
    const auto thetaIntegral = [&](double v) {  // h(v) x the integral over u
        const V3d xv = a + d * v, rel = xv - o;
        const double delta = w.dot(rel), h = (rel - w * delta).length();
        return gaussLegendre(
            [&](double theta) {
                const double u = delta + h * std::tan(theta);
                const V3d diff = o + w * u - xv;
                const double dist = diff.length();
                const V3d n = diff / dist;
                return expD(-m.sigmaT * (u + dist)) * (hg(m.g, d.dot(n)) * hg(m.g, -n.dot(w)));
            },
            std::atan2(-delta, h), std::atan2(s - delta, h), panels);
    };
    const V3d r = a - o, rPerp = r - w * w.dot(r), dPerp = d - w * w.dot(d);
    const double sinT = dPerp.length();
    V3d integral;
    if (sinT < 1e-9) {  // parallel: h is constant
        const double h = rPerp.length();
        integral = gaussLegendre([&](double v) { return thetaIntegral(v) / h; }, 0.0, t, panels);
    } else {
        const double v0 = -rPerp.dot(dPerp) / (sinT * sinT);
        const double h0 = std::max((rPerp + dPerp * v0).length(), 1e-300);
        integral = gaussLegendre([&](double alpha) { return thetaIntegral(v0 + h0 * std::sinh(alpha) / sinT) / sinT; },
                                 std::asinh(-sinT * v0 / h0), std::asinh(sinT * (t - v0) / h0), panels);
    }
    return integral * toD(seg.throughputBefore) * toD(vrl.flux) * m.sigmaS * m.sigmaS;
}

struct Reference {
    V3d value;
    double relativeError = 0.0;  // change at the last panel doubling, relative to the largest channel
};

// Doubles the panels (16 .. 256, i.e. 128 .. 2048 nodes per variable) until the
// value changes by less than 1e-6 of its largest channel.
Reference reference(const Vrl& vrl, const CameraSegment& seg, const MediumParams& m) {
    V3d coarse = quadrature(vrl, seg, m, 16);
    double change = kInfD;
    for (int panels = 32; panels <= 256; panels *= 2) {
        const V3d fine = quadrature(vrl, seg, m, panels);
        const double scale = std::max({std::abs(fine.x), std::abs(fine.y), std::abs(fine.z)});
        change = 0.0;
        for (int c = 0; c < 3; ++c) change = std::max(change, std::abs(fine[c] - coarse[c]));
        change = scale > 0.0 ? change / scale : 0.0;
        coarse = fine;
        if (change < 1e-6) break;
    }
    return {coarse, change};
}

// ---- Estimator sampling -------------------------------------------------------------

struct SampleStats {
    V3d mean{0.0}, se{0.0};
    double maxSample = 0.0;
};

SampleStats sampleEstimator(CaseResult& r, const VrlEstimator& estimator, const Vrl& vrl, const CameraSegment& seg,
                            int n, uint64_t seed) {
    Rng rng(seed, 0);
    V3d sum(0.0), sum2(0.0);
    SampleStats s;
    for (int i = 0; i < n; ++i) {
        const Rgb c = estimator.contribution(vrl, seg, rng);
        checkValue(r, c);
        const V3d x = toD(c);
        sum += x;
        sum2 += x * x;
        s.maxSample = std::max(s.maxSample, double(maxComponent(c)));
    }
    s.mean = sum / double(n);
    for (int c = 0; c < 3; ++c)
        s.se[c] = std::sqrt(std::max(0.0, (sum2[c] / n - s.mean[c] * s.mean[c])) / double(n - 1));
    return s;
}

// Estimator mean against the quadrature, per channel. The allowance is the
// quadrature's convergence (x 10, at least 1e-5 relative) plus 1e-35 absolute
// (float underflow of channels that are ~0).
void expectUnbiased(CaseResult& r, const Scene& scene, const Vrl& vrl, const CameraSegment& seg, int n,
                    uint64_t seed, const std::string& label) {
    const VrlEstimator estimator(scene, 1);
    const MediumParams m = paramsOf(scene.media()[seg.medium]);
    const Reference ref = reference(vrl, seg, m);
    const SampleStats s = sampleEstimator(r, estimator, vrl, seg, n, seed);
    for (int c = 0; c < 3; ++c) {
        checkValue(r, ref.value[c]);
        const double allowance = std::max(1e-5, 10.0 * ref.relativeError) * std::abs(ref.value[c]) + 1e-35;
        compare(r, format("%s, channel %d: z (mean %.4g, quadrature %.4g, SE %.2g)", label.c_str(), c, s.mean[c],
                          ref.value[c], s.se[c]),
                zScore(s.mean[c], s.se[c], ref.value[c], allowance), kZ);
    }
}

Vrl makeVrl(const V3d& origin, const V3d& direction, double length, const Rgb& flux = Rgb(1.0f), int medium = 0) {
    Vrl v;
    v.origin = toF(origin);
    v.direction = toF(direction.normalized()).normalized();
    v.length = float(length);
    v.flux = flux;
    v.medium = medium;
    return v;
}

CameraSegment makeSegment(const V3d& origin, const V3d& direction, double length, const Rgb& before = Rgb(1.0f),
                          int medium = 0) {
    CameraSegment s;
    s.origin = toF(origin);
    s.direction = toF(direction.normalized()).normalized();
    s.length = float(length);
    s.medium = medium;
    s.throughputBefore = before;
    return s;
}

V3d uniformDirection(Rng& rng) {
    const double z = 1.0 - 2.0 * rng.nextDouble(), phi = 2.0 * kPiD * rng.nextDouble();
    const double rr = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {rr * std::cos(phi), rr * std::sin(phi), z};
}
V3d uniformInCube(Rng& rng, double half) {
    return V3d(2 * rng.nextDouble() - 1, 2 * rng.nextDouble() - 1, 2 * rng.nextDouble() - 1) * half;
}

struct Pair {
    Vrl vrl;
    CameraSegment seg;
};

// `count` random (VRL, segment) pairs at geometric scale `scale` (origins in the
// cube of half-size scale, VRL lengths 0.2 .. 1.5 scale, camera lengths 0.5 .. 3
// scale), from the stream (seed, 0).
std::vector<Pair> randomPairs(int count, double scale, uint64_t seed, const Rgb& flux = Rgb(1.0f)) {
    Rng rng(seed, 0);
    std::vector<Pair> pairs;
    for (int i = 0; i < count; ++i) {
        const V3d vo = uniformInCube(rng, scale), vd = uniformDirection(rng);
        const double vl = (0.2 + 1.3 * rng.nextDouble()) * scale;
        const V3d so = uniformInCube(rng, scale), sd = uniformDirection(rng);
        const double sl = (0.5 + 2.5 * rng.nextDouble()) * scale;
        const float before = float(0.3 + 0.7 * rng.nextDouble());
        pairs.push_back({makeVrl(vo, vd, vl, flux), makeSegment(so, sd, sl, Rgb(before))});
    }
    return pairs;
}

// ---- Light-tree checks ---------------------------------------------------------------------

bool allIsotropic(const Scene& scene) {
    return std::all_of(scene.media().begin(), scene.media().end(), [](const auto& m) { return m.phase().isIsotropic(); });
}

// Every node of `tree` against every segment: a crossing line gives an infinite
// bound; otherwise `samples` estimates of the node (its representative carrying the
// cluster flux, as the cut evaluates it) must not exceed the bound in any channel.
// Counted into boundChecks / boundViolations (asserted only in isotropic media).
void checkClusterBounds(CaseResult& r, const Scene& scene, const LightTree& tree,
                        const std::vector<CameraSegment>& segments, int samples, uint64_t seed) {
    const ClusterBound bound(scene, tree);
    const VrlEstimator estimator(scene, 1);
    if (!allIsotropic(scene)) r.boundAsserted = false;
    uint64_t crossing = 0;
    for (size_t k = 0; k < segments.size(); ++k) {
        for (size_t n = 0; n < tree.nodes().size(); ++n) {
            const LightTreeNode& node = tree.nodes()[n];
            bool crosses = false;
            const Rgb b = bound.bound(int32_t(n), segments[k], &crosses);
            if (crosses) {
                ++crossing;
                require(r, std::isinf(b.x) && std::isinf(b.y) && std::isinf(b.z) && minComponent(b) > 0.0f,
                        "a crossing node's bound is not +infinity");
                continue;
            }
            checkValue(r, b);
            Vrl representative = tree.vrls()[node.representative];
            representative.flux = node.clusterFlux;
            for (int s = 0; s < samples; ++s) {
                Rng rng(seed, Rng::combine(k * 1000003 + n, uint64_t(s)));
                const Rgb e = estimator.contribution(representative, segments[k], rng);
                checkValue(r, e);
                ++r.boundChecks;
                if (e.x > b.x || e.y > b.y || e.z > b.z) ++r.boundViolations;
            }
        }
    }
    if (crossing) note(r, format("%llu (node, segment) pairs crossed: infinite bound", (unsigned long long)crossing));
}

// Lightcuts at threshold 0 (no cut-size limit) against the plain sum over the
// tree's VRLs with the same streams: equal up to float accumulation (the cut adds
// and subtracts inner-node estimates); tolerance accumulationTolerance(N) of the
// largest channel of the plain sum. (Nodes whose bound is
// exactly 0 stay unrefined even at threshold 0: their VRLs contribute exactly 0.)
// Also runs the default threshold 0.02 and checks its result's sign and finiteness.
void checkCutAgainstPlain(CaseResult& r, const Scene& scene, const LightTree& tree,
                          const std::vector<CameraSegment>& segments, uint64_t streamBase, const std::string& label,
                          double tolerance = -1.0) {
    if (tolerance < 0.0) tolerance = accumulationTolerance(tree.vrls().size());
    const VrlEstimator estimator(scene, 1);
    CutSettings exact;
    exact.errorThreshold = 0.0f;
    exact.maxCutSize = std::numeric_limits<uint32_t>::max();
    const LightcutsEstimator cutExact(scene, tree, estimator, exact);
    const LightcutsEstimator cutDefault(scene, tree, estimator, CutSettings{});
    double worst = 0.0, worstDefault = 0.0;
    for (size_t i = 0; i < segments.size(); ++i) {
        const uint64_t key = Rng::combine(streamBase, i);
        V3d plain(0.0);
        for (uint32_t k = 0; k < tree.vrls().size(); ++k) {
            Rng rng = vrlStream(key, k);
            const Rgb c = estimator.contribution(tree.vrls()[k], segments[i], rng);
            checkValue(r, c);
            plain += toD(c);
        }
        CutStatistics statistics;
        const Rgb cut = cutExact.estimate(segments[i], key, statistics);
        checkValue(r, cut);
        const double scale = std::max({plain.x, plain.y, plain.z});
        for (int c = 0; c < 3; ++c)
            worst = std::max(worst, scale > 0.0 ? std::abs(cut[c] - plain[c]) / scale : std::abs(double(cut[c])));
        CutStatistics defaultStatistics;
        const Rgb approx = cutDefault.estimate(segments[i], key, defaultStatistics);
        checkValue(r, approx);
        if (allIsotropic(scene)) {
            r.boundChecks += defaultStatistics.boundedEstimates + statistics.boundedEstimates;
            r.boundViolations += defaultStatistics.boundExceeded + statistics.boundExceeded;
        }
        for (int c = 0; c < 3; ++c)
            worstDefault = std::max(worstDefault, scale > 0.0 ? std::abs(approx[c] - plain[c]) / scale : 0.0);
    }
    compare(r, label + ": Lightcuts at threshold 0 vs plain VRLs, rel. diff", worst, tolerance);
    note(r, format("%s: threshold 0.02 vs plain, largest rel. diff %.3g over %zu segments", label.c_str(),
                   worstDefault, segments.size()));
}

// ---- Image-level helpers ---------------------------------------------------------------------

struct ImageStats {
    V3d mean{0.0}, se{0.0};  // over runs of the image mean (per channel)
    std::vector<V3d> runs;
    double seconds = 0.0;
};

// `runs` renders with seeds seedBase + run. Every pixel of the image and of each
// transport layer must be finite and >= 0 (the cut statistics layers too); the
// bound counters of Lightcuts renders go into the case (isotropic: asserted).
ImageStats renderRuns(CaseResult& r, const Scene& scene, RenderSettings settings, int runs, uint64_t seedBase) {
    ImageStats s;
    const auto start = std::chrono::steady_clock::now();
    for (int run = 0; run < runs; ++run) {
        settings.seed = seedBase + uint64_t(run);
        RenderStatistics statistics;
        const ImageSet out = render(scene, settings, {}, &statistics);
        V3d sum(0.0);
        for (const Rgb& p : out.image.pixels()) {
            checkValue(r, p);
            sum += toD(p);
        }
        for (const auto& [name, layer] : out.layers)
            for (const Rgb& p : layer.pixels()) checkValue(r, p);
        if (usesLightTree(settings.method)) {
            if (!allIsotropic(scene)) r.boundAsserted = false;
            r.boundChecks += statistics.boundedEstimates;
            r.boundViolations += statistics.boundExceeded;
        }
        s.runs.push_back(sum / double(out.image.pixelCount()));
    }
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (const V3d& m : s.runs) s.mean += m / double(runs);
    for (int c = 0; c < 3; ++c) {
        double ss = 0.0;
        for (const V3d& m : s.runs) ss += (m[c] - s.mean[c]) * (m[c] - s.mean[c]);
        s.se[c] = runs > 1 ? std::sqrt(ss / double(runs - 1) / double(runs)) : 0.0;
    }
    return s;
}

// Two independent sets of runs: per channel |difference| in combined standard errors.
void compareRuns(CaseResult& r, const std::string& label, const ImageStats& a, const ImageStats& b,
                 double relativeAllowance = 0.0) {
    for (int c = 0; c < 3; ++c) {
        const double se = std::hypot(a.se[c], b.se[c]);
        const double allowance = relativeAllowance * std::abs(b.mean[c]) + 1e-30;
        compare(r, format("%s, channel %d: t (%.5g vs %.5g, SE %.2g)", label.c_str(), c, a.mean[c], b.mean[c], se),
                zScore(a.mean[c], se, b.mean[c], allowance), kImageZ);
    }
}

// Runs against an analytic value per channel.
void compareAnalytic(CaseResult& r, const std::string& label, const ImageStats& a, const V3d& expected,
                     double relativeAllowance) {
    for (int c = 0; c < 3; ++c) {
        const double allowance = relativeAllowance * std::abs(expected[c]) + 1e-30;
        compare(r, format("%s, channel %d: t (%.6g vs analytic %.6g, SE %.2g)", label.c_str(), c, a.mean[c],
                          expected[c], a.se[c]),
                zScore(a.mean[c], a.se[c], expected[c], allowance), kImageZ);
    }
}

RenderSettings methodSettings(const std::string& method, int spp, uint64_t vrls) {
    RenderSettings s;
    s.method = method;
    s.samplesPerPixel = spp;
    s.vrlCount = vrls;
    s.tileSize = 4;
    return s;
}

// A closed sphere of radius `radius` around the camera emitting `radiance` inwards,
// black walls, filled with medium (sigmaS, sigmaA, g). Non-absorbing: every pixel's
// expected radiance is exactly `radiance` (each camera path ends on the wall);
// pure absorber: radiance exp(-sigma_t t), t the distance to the (tessellated) wall.
SceneDescription furnace(const Rgb& radiance, const Rgb& sigmaS, const Rgb& sigmaA, float g, int side = 4) {
    SceneDescription scene;
    scene.sensor = test::cameraAtOrigin(side, side, 90.0f);
    scene.media.push_back(mediumDescription(sigmaS, sigmaA, g));
    scene.sensor.medium = 0;
    ShapeDescription sphere;
    sphere.kind = ShapeDescription::Kind::Sphere;
    sphere.radius = 1.0f;
    sphere.flipNormals = true;
    sphere.bsdf = test::diffuseBsdf(Rgb(0.0f), false);
    sphere.areaRadiance = radiance;
    sphere.exteriorMedium = 0;  // flipped: the inside is the exterior side
    scene.shapes.push_back(sphere);
    return scene;
}

const std::vector<std::string> kAllMethods = {"path", "vrl", "vrl-lightcuts", "vpl-lightcuts"};

// The furnace: every method's image mean (K runs) against radiance 1 per channel,
// allowing `bias` (relative) for media that absorb a little.
void furnaceAllMethods(CaseResult& r, const Rgb& sigmaS, const Rgb& sigmaA, float g, double bias, int runs,
                       int pathSpp, int vrlSpp, uint64_t vrls) {
    const auto scene = Scene::build(furnace(Rgb(1.0f), sigmaS, sigmaA, g));
    for (const std::string& method : kAllMethods) {
        const ImageStats s = renderRuns(r, *scene, methodSettings(method, method == "path" ? pathSpp : vrlSpp, vrls),
                                        runs, 100);
        compareAnalytic(r, method, s, V3d(1.0), bias + 1e-5);
        note(r, format("%s: mean (%.5f %.5f %.5f) +- (%.2g %.2g %.2g), %.2f s", method.c_str(), s.mean.x, s.mean.y,
                       s.mean.z, s.se.x, s.se.y, s.se.z, s.seconds));
    }
}

// ================================================================================================
// Cases: media
// ================================================================================================

// sigma_t = 10^e (albedo 0.5, isotropic): 4 random pairs at geometric scale
// min(1, 1 / sigma_t) against the quadrature (5e4 samples each), one unit-scale
// pair (underflowing to 0 in thick media), and a 24-VRL tree: bounds on 4 segments,
// threshold-0 cut against plain VRLs.
void sigmaTCase(CaseResult& r, double sigmaT) {
    r.description = format("VRL estimator, sigma_t = %g, albedo 0.5: 4 pairs at scale min(1, 1/sigma_t) + 1 at "
                           "scale 1 vs quadrature; 24-VRL tree bounds and threshold-0 cut",
                           sigmaT);
    const auto scene = unboundedScene(Rgb(float(0.5 * sigmaT)), Rgb(float(0.5 * sigmaT)), 0.0f);
    const double scale = std::min(1.0, 1.0 / sigmaT);
    const auto pairs = randomPairs(4, scale, 31);
    for (size_t i = 0; i < pairs.size(); ++i)
        expectUnbiased(r, *scene, pairs[i].vrl, pairs[i].seg, 50'000, 1000 + i, format("pair %zu", i));
    const auto unit = randomPairs(1, 1.0, 32)[0];
    expectUnbiased(r, *scene, unit.vrl, unit.seg, 20'000, 1010, "unit-scale pair");
    std::vector<Vrl> vrls;
    std::vector<CameraSegment> segments;
    for (const auto& p : randomPairs(24, scale, 33)) vrls.push_back(p.vrl);
    for (const auto& p : randomPairs(4, scale, 34)) segments.push_back(p.seg);
    const LightTree tree = LightTree::build(vrls);
    checkClusterBounds(r, *scene, tree, segments, 64, 35);
    checkCutAgainstPlain(r, *scene, tree, segments, 36, "tree");
}

void albedoCase(CaseResult& r, double albedo) {
    r.description = format("VRL estimator, sigma_t = 1, albedo %g: 4 pairs vs quadrature; 24-VRL tree bounds "
                           "and threshold-0 cut%s",
                           albedo, albedo == 0.0 ? "; every estimate and bound exactly 0" : "");
    const auto scene = unboundedScene(Rgb(float(albedo)), Rgb(float(1.0 - albedo)), 0.0f);
    const auto pairs = randomPairs(4, 1.0, 41);
    for (size_t i = 0; i < pairs.size(); ++i)
        expectUnbiased(r, *scene, pairs[i].vrl, pairs[i].seg, 50'000, 1100 + i, format("pair %zu", i));
    std::vector<Vrl> vrls;
    std::vector<CameraSegment> segments;
    for (const auto& p : randomPairs(24, 1.0, 42)) vrls.push_back(p.vrl);
    for (const auto& p : randomPairs(4, 1.0, 43)) segments.push_back(p.seg);
    const LightTree tree = LightTree::build(vrls);
    checkClusterBounds(r, *scene, tree, segments, 64, 44);
    checkCutAgainstPlain(r, *scene, tree, segments, 45, "tree");
    if (albedo == 0.0) {
        const ClusterBound bound(*scene, tree);
        const VrlEstimator estimator(*scene, 1);
        Rng rng(46, 0);
        for (const auto& seg : segments) {
            for (size_t n = 0; n < tree.nodes().size(); ++n) {
                bool crosses = false;
                const Rgb b = bound.bound(int32_t(n), seg, &crosses);
                if (!crosses) require(r, isBlack(b), "albedo 0: a bound is not exactly 0");
            }
            for (const Vrl& v : vrls) require(r, isBlack(estimator.contribution(v, seg, rng)), "albedo 0: nonzero estimate");
        }
    }
}

void hgCase(CaseResult& r, float g) {
    r.description = format("VRL estimator, HG g = %g (sigma_s 0.5, sigma_a 0.2): 4 pairs vs quadrature (2e5 "
                           "samples each); 24-VRL tree: threshold-0 cut; bound (a heuristic for HG) violations reported",
                           g);
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), g);
    const auto pairs = randomPairs(4, 1.0, 51);
    for (size_t i = 0; i < pairs.size(); ++i)
        expectUnbiased(r, *scene, pairs[i].vrl, pairs[i].seg, 200'000, 1200 + i, format("pair %zu", i));
    std::vector<Vrl> vrls;
    std::vector<CameraSegment> segments;
    for (const auto& p : randomPairs(24, 1.0, 52)) vrls.push_back(p.vrl);
    for (const auto& p : randomPairs(4, 1.0, 53)) segments.push_back(p.seg);
    const LightTree tree = LightTree::build(vrls);
    checkClusterBounds(r, *scene, tree, segments, 64, 54);
    checkCutAgainstPlain(r, *scene, tree, segments, 55, "tree");
    note(r, format("HG bound x (1 + epsilon = 2) exceeded by %llu of %llu samples (heuristic, not asserted)",
                   (unsigned long long)r.boundViolations, (unsigned long long)r.boundChecks));
}

void chromaticEstimatorCase(CaseResult& r) {
    r.description = "VRL estimator, sigma_t = (1e-2, 1, 1e2) (channels differ by 1e4), albedo 0.5: 4 pairs at "
                    "scale 0.05 and 2 at scale 1 vs quadrature per channel; 24-VRL tree bounds and threshold-0 cut";
    const Rgb sigmaT(1e-2f, 1.0f, 1e2f);
    const auto scene = unboundedScene(sigmaT * 0.5f, sigmaT * 0.5f, 0.0f);
    const auto pairs = randomPairs(4, 0.05, 61, Rgb(1.0f, 2.0f, 3.0f));
    for (size_t i = 0; i < pairs.size(); ++i)
        expectUnbiased(r, *scene, pairs[i].vrl, pairs[i].seg, 50'000, 1300 + i, format("pair %zu", i));
    const auto unit = randomPairs(2, 1.0, 62, Rgb(1.0f, 2.0f, 3.0f));
    for (size_t i = 0; i < unit.size(); ++i)
        expectUnbiased(r, *scene, unit[i].vrl, unit[i].seg, 50'000, 1310 + i, format("unit pair %zu", i));
    std::vector<Vrl> vrls;
    std::vector<CameraSegment> segments;
    for (const auto& p : randomPairs(24, 0.05, 63, Rgb(1.0f, 2.0f, 3.0f))) vrls.push_back(p.vrl);
    for (const auto& p : randomPairs(4, 0.05, 64)) segments.push_back(p.seg);
    const LightTree tree = LightTree::build(vrls);
    checkClusterBounds(r, *scene, tree, segments, 64, 65);
    checkCutAgainstPlain(r, *scene, tree, segments, 66, "tree");
}

// Image level: the furnace (L = 1 exactly) for every method.
void furnaceCase(CaseResult& r, const Rgb& sigmaS, const Rgb& sigmaA, float g, double bias, const char* what,
                 uint64_t vrls = 8000) {
    r.description = format("furnace (emitting sphere, camera inside, black walls): %s; every method's image "
                           "mean against the analytic radiance 1 (8 runs)",
                           what);
    furnaceAllMethods(r, sigmaS, sigmaA, g, bias, 8, 1024, 16, vrls);
}

// Images in an HG g = +-0.99 furnace. Every estimator here (next-event estimation in
// the path tracer and in part (b), VRLs, VPLs) is unbiased but heavy-tailed at such
// a peaked phase function (f reaches (1 + g) / (1 - g)^2 / (4 pi) ~ 1.6e3), so the
// image means are reported, not compared with the analytic 1. Checked exactly:
// part (a) is exp(-sigma_t t) per pixel (rel. 1e-5); Lightcuts at threshold 0
// reproduce plain VRLs, and VPL Lightcuts at threshold 0 plain VPLs, with the same
// seed (largest per-pixel difference relative to the image's largest pixel, 1e-4).
void hgImageCase(CaseResult& r, float g) {
    r.description = format("furnace images at HG g = %g (sigma_s = 1): every value finite and >= 0; part (a) "
                           "against exp(-sigma_t t); Lightcuts and VPL Lightcuts at threshold 0 against plain VRLs "
                           "and VPLs (same seed); the means (heavy-tailed here) and HG bound violations reported",
                           g);
    const auto scene = Scene::build(furnace(Rgb(1.0f), Rgb(1.0f), Rgb(0.0f), g));
    const auto image = [&](const std::string& method, float threshold) {
        RenderSettings settings = methodSettings(method, method == "path" ? 256 : 8, 3000);
        settings.seed = 9;
        settings.cut.errorThreshold = threshold;
        settings.cut.maxCutSize = std::numeric_limits<uint32_t>::max();
        RenderStatistics statistics;
        ImageSet out = render(*scene, settings, {}, &statistics);
        for (const Rgb& p : out.image.pixels()) checkValue(r, p);
        for (const auto& layer : out.layers)
            for (const Rgb& p : layer.second.pixels()) checkValue(r, p);
        if (usesLightTree(method) && threshold > 0.0f) {
            r.boundAsserted = false;
            r.boundChecks += statistics.boundedEstimates;
            r.boundViolations += statistics.boundExceeded;
        }
        double mean = 0.0;
        for (const Rgb& p : out.image.pixels()) mean += p.y / double(out.image.pixelCount());
        note(r, format("%s%s: mean %.4f", method.c_str(), threshold == 0.0f ? " (threshold 0)" : "", mean));
        return out;
    };
    const auto largestDifference = [](const Image& a, const Image& b) {
        double scale = 0.0, worst = 0.0;
        for (size_t i = 0; i < a.pixelCount(); ++i) scale = std::max(scale, double(maxComponent(b[i])));
        for (size_t i = 0; i < a.pixelCount(); ++i)
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(a[i][c]) - double(b[i][c])));
        return scale > 0.0 ? worst / scale : worst;
    };
    image("path", 0.02f);
    const ImageSet vrl = image("vrl", 0.02f);
    image("vrl-lightcuts", 0.02f);
    image("vpl-lightcuts", 0.02f);
    compare(r, "vrl-lightcuts at threshold 0 vs vrl, largest pixel difference / largest pixel",
            largestDifference(image("vrl-lightcuts", 0.0f).image, vrl.image), 1e-4);
    compare(r, "vpl-lightcuts at threshold 0 vs vpl, largest pixel difference / largest pixel",
            largestDifference(image("vpl-lightcuts", 0.0f).image, image("vpl", 0.0f).image), 1e-4);
    double worst = 0.0;
    for (int y = 0; y < vrl.image.height(); ++y) {
        for (int x = 0; x < vrl.image.width(); ++x) {
            const Ray ray = scene->camera().generateRay(x + 0.5f, y + 0.5f);
            const auto hit = scene->intersect(ray);
            if (!hit) continue;
            const double expected = std::exp(-double(hit->t - ray.tMin));
            worst = std::max(worst, std::abs(vrl.layers[0].second.at(x, y).x - expected) / expected);
        }
    }
    compare(r, "part (a) vs exp(-sigma_t t), largest rel. diff per pixel", worst, 1e-5);
    note(r, format("HG bound x (1 + epsilon = 2) exceeded by %llu of %llu inner-node estimates (heuristic, not "
                   "asserted)",
                   (unsigned long long)r.boundViolations, (unsigned long long)r.boundChecks));
}

// Pure absorber in the furnace: deterministic, exp(-sigma_t t) per pixel.
void absorbingFurnaceCase(CaseResult& r) {
    r.description = "furnace with albedo 0 (pure absorber), sigma_t = 1 and 1e4: every method, every pixel against "
                    "exp(-sigma_t t) (t: distance to the tessellated wall), rel. diff <= 1e-5 (+1e-30 absolute)";
    for (const float sigmaT : {1.0f, 1e4f}) {
        const auto scene = Scene::build(furnace(Rgb(1.0f), Rgb(0.0f), Rgb(sigmaT), 0.0f));
        for (const std::string& method : kAllMethods) {
            RenderSettings settings = methodSettings(method, 2, 500);
            settings.seed = 5;
            const ImageSet out = render(*scene, settings);
            double worst = 0.0;
            for (int y = 0; y < out.image.height(); ++y) {
                for (int x = 0; x < out.image.width(); ++x) {
                    const Ray ray = scene->camera().generateRay(x + 0.5f, y + 0.5f);
                    const auto hit = scene->intersect(ray);
                    if (!hit) {
                        fail(r, "a camera ray misses the furnace wall");
                        continue;
                    }
                    const double expected = std::exp(-double(sigmaT) * double(hit->t - ray.tMin));
                    for (int c = 0; c < 3; ++c) {
                        checkValue(r, out.image.at(x, y)[c]);
                        const double d = std::abs(out.image.at(x, y)[c] - expected);
                        worst = std::max(worst, d <= 1e-30 ? 0.0 : d / expected);
                    }
                }
            }
            compare(r, format("%s, sigma_t %g: largest rel. diff per pixel", method.c_str(), sigmaT), worst, 1e-5);
        }
    }
}

// ================================================================================================
// Cases: geometry
// ================================================================================================

const V3d kZ3(0, 0, 1);
CameraSegment zSegment(double length = 2.0) { return makeSegment(V3d(0.0), kZ3, length, Rgb(0.9f)); }

void parallelCase(CaseResult& r) {
    r.description = "camera ray parallel (and antiparallel) to a VRL at offsets 0.3, 1e-3, 1e-6, isotropic and HG "
                    "g = 0.7: estimator vs quadrature; tree of the parallel VRLs: bounds, threshold-0 cut";
    std::vector<Vrl> vrls;
    for (const float g : {0.0f, 0.7f}) {
        const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), g);
        int i = 0;
        for (const double offset : {0.3, 1e-3, 1e-6}) {
            for (const double sign : {1.0, -1.0}) {
                const Vrl v = makeVrl(V3d(offset, 0.0, sign > 0 ? 0.4 : 1.4), kZ3 * sign, 1.0);
                expectUnbiased(r, *scene, v, zSegment(), 50'000, 1400 + i++,
                               format("g %g, offset %g, %s", g, offset, sign > 0 ? "parallel" : "antiparallel"));
                if (g == 0.0f) vrls.push_back(v);
            }
        }
    }
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const LightTree tree = LightTree::build(vrls);
    const std::vector<CameraSegment> segments = {zSegment(), zSegment(1e30), makeSegment(V3d(0, 0, -5), kZ3, 3.0)};
    checkClusterBounds(r, *scene, tree, segments, 256, 1410);
    checkCutAgainstPlain(r, *scene, tree, segments, 1411, "parallel tree");
}

// A VRL along +x through the point (0, offset, 1) (crossing the z axis at z = 1 when offset = 0).
Vrl crossingVrl(double offset) { return makeVrl(V3d(-0.5, offset, 0.85), V3d(1, 0, 0.3), 1.0); }

void crossingCase(CaseResult& r) {
    r.description = "VRL crossing the camera ray: near-crossing at 1e-2, 1e-4, 1e-6 vs quadrature (the integral "
                    "grows like log(1/offset)); exact crossing: finite samples, infinite bound, cut = plain";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    int i = 0;
    double previous = 0.0;
    for (const double offset : {1e-2, 1e-4, 1e-6}) {
        const Vrl v = crossingVrl(offset);
        expectUnbiased(r, *scene, v, zSegment(), 100'000, 1500 + i++, format("offset %g", offset));
        const double q = reference(v, zSegment(), paramsOf(scene->media()[0])).value.x;
        require(r, q > previous, "the near-crossing integral must grow as the offset shrinks");
        previous = q;
    }
    const VrlEstimator estimator(*scene, 1);
    const SampleStats exact = sampleEstimator(r, estimator, crossingVrl(0.0), zSegment(), 100'000, 1510);
    note(r, format("exact crossing: sample mean %.4g (true integral infinite), largest sample %.3g", exact.mean.x,
                   exact.maxSample));
    std::vector<Vrl> vrls = {crossingVrl(0.0), crossingVrl(1e-6), crossingVrl(1e-2)};
    Rng rng(1511, 0);
    for (int k = 0; k < 13; ++k) vrls.push_back(makeVrl(uniformInCube(rng, 1.0), uniformDirection(rng), 0.5));
    const LightTree tree = LightTree::build(vrls);
    const ClusterBound bound(*scene, tree);
    bool crosses = false;
    bound.bound(0, zSegment(), &crosses);
    require(r, crosses, "the exactly crossing VRL's leaf must report a crossing (infinite bound)");
    checkClusterBounds(r, *scene, tree, {zSegment(), zSegment(1e30)}, 256, 1512);
    checkCutAgainstPlain(r, *scene, tree, {zSegment(), zSegment(1e30)}, 1513, "crossing tree");
}

void touchingCase(CaseResult& r) {
    r.description = "touching: VRL starting on / ending on the camera segment, camera segment starting on the VRL "
                    "(finite, >= 0, infinite bound, cut = plain); near-touching at 1e-6 vs quadrature";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const VrlEstimator estimator(*scene, 1);
    const V3d dir(1, 0, 0.2);
    const Vrl starts = makeVrl(V3d(0, 0, 1.0), dir, 1.0);
    const Vrl ends = makeVrl(V3d(0, 0, 1.0) - dir.normalized() * 1.0, dir, 1.0);
    const Vrl nearStart = makeVrl(V3d(1e-6, 0, 1.0), dir, 1.0);
    const CameraSegment fromVrl = makeSegment(toD(crossingVrl(0.0).origin) + V3d(1, 0, 0.3).normalized() * 0.5,
                                              V3d(0, 1, 0), 2.0);
    for (const auto& [vrl, seg, name] : {std::tuple{starts, zSegment(), "VRL starting on the segment"},
                                         std::tuple{ends, zSegment(), "VRL ending on the segment"},
                                         std::tuple{crossingVrl(0.0), fromVrl, "segment starting on the VRL"}}) {
        const SampleStats s = sampleEstimator(r, estimator, vrl, seg, 50'000, 1600);
        note(r, format("%s: sample mean %.4g (true integral infinite)", name, s.mean.x));
        const LightTree single = LightTree::build({vrl});
        bool crosses = false;
        ClusterBound(*scene, single).bound(0, seg, &crosses);
        require(r, crosses, std::string(name) + ": the bound must be infinite");
    }
    expectUnbiased(r, *scene, nearStart, zSegment(), 100'000, 1601, "VRL starting 1e-6 from the segment");
    const LightTree tree = LightTree::build({starts, ends, nearStart, crossingVrl(0.0)});
    checkCutAgainstPlain(r, *scene, tree, {zSegment(), fromVrl}, 1602, "touching tree");
    checkClusterBounds(r, *scene, tree, {zSegment(), fromVrl}, 256, 1603);
}

// Collinear and disjoint: the VRL on the camera line beyond the segment's end
// (both directions). Both phase cosines are +-1, so
//   L = Tb Phi sigma_s^2 fV fU int_0^t e^{-sigma_t p(v)} (1 / (p - S) - 1 / p) dv,  p(v) = a +- v,
// a 1D integral (Gauss-Legendre, 64 panels; smooth since p - S >= 0.5).
double collinearReference(double a, double sign, double t, double S, const MediumParams& m, int c,
                          double before) {
    const double fV = hg(m.g, -sign), fU = hg(m.g, 1.0);
    const V3d v = gaussLegendre(
        [&](double x) {
            const double p = a + sign * x;
            return V3d(std::exp(-m.sigmaT[c] * p) * (1.0 / (p - S) - 1.0 / p));
        },
        0.0, t, 64);
    return before * m.sigmaS[c] * m.sigmaS[c] * fV * fU * v.x;
}

void collinearCase(CaseResult& r) {
    r.description = "collinear: VRL on the camera line beyond the segment, same and opposite direction, isotropic "
                    "and HG g = +-0.9, vs the closed-form 1D integral; VRL lying on the segment (infinite "
                    "integral): finite samples, infinite bound, cut = plain";
    int i = 0;
    for (const float g : {0.0f, 0.9f, -0.9f}) {
        const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), g);
        const VrlEstimator estimator(*scene, 1);
        const MediumParams m = paramsOf(scene->media()[0]);
        for (const double sign : {1.0, -1.0}) {
            const double a = sign > 0 ? 2.5 : 3.5;  // the VRL covers z in [2.5, 3.5] either way
            const Vrl v = makeVrl(V3d(0, 0, a), kZ3 * sign, 1.0);
            const SampleStats s = sampleEstimator(r, estimator, v, zSegment(), 100'000, 1700 + i++);
            for (int c = 0; c < 3; ++c) {
                const double ref = collinearReference(a, sign, 1.0, 2.0, m, c, 0.9);
                compare(r, format("g %g, %s, channel %d: z (mean %.5g, analytic %.5g)", g,
                                  sign > 0 ? "same direction" : "opposite direction", c, s.mean[c], ref),
                        zScore(s.mean[c], s.se[c], ref, 1e-5 * ref), kZ);
            }
        }
    }
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const VrlEstimator estimator(*scene, 1);
    const Vrl on = makeVrl(V3d(0, 0, 0.5), kZ3, 1.0);
    const SampleStats s = sampleEstimator(r, estimator, on, zSegment(), 50'000, 1710);
    note(r, format("VRL on the segment: sample mean %.4g (true integral infinite)", s.mean.x));
    std::vector<Vrl> vrls = {on, makeVrl(V3d(0, 0, 2.5), kZ3, 1.0), makeVrl(V3d(0, 0, -1.5), -kZ3, 1.0),
                             makeVrl(V3d(0, 0, 0.2), -kZ3, 0.1)};
    const LightTree tree = LightTree::build(vrls);
    const ClusterBound bound(*scene, tree);
    for (size_t n = 0; n < tree.nodes().size(); ++n) {
        bool crosses = false;
        bound.bound(int32_t(n), zSegment(), &crosses);
        require(r, crosses, "every node on the camera line must have an infinite bound");
    }
    checkCutAgainstPlain(r, *scene, tree, {zSegment(), makeSegment(V3d(0.1, 0, 0), kZ3, 2.0)}, 1711, "collinear tree");
    checkClusterBounds(r, *scene, tree, {makeSegment(V3d(0.1, 0, 0), kZ3, 2.0)}, 256, 1712);
}

void shortVrlCase(CaseResult& r) {
    r.description = "VRLs of length 1e-7 (generic, 1e-3 from the camera line, parallel 1e-3 away) vs quadrature; a "
                    "tree of 1e-7 VRLs (cluster flux = flux x length / 1e-7): bounds, threshold-0 cut";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const std::vector<std::pair<Vrl, const char*>> cases = {
        {makeVrl(V3d(0.3, 0.2, 0.7), V3d(1, 2, 3), 1e-7), "generic"},
        {makeVrl(V3d(1e-3, 0, 0.7), V3d(0, 1, 0), 1e-7), "1e-3 from the line"},
        {makeVrl(V3d(1e-3, 0, 0.7), kZ3, 1e-7), "parallel, 1e-3 away"}};
    int i = 0;
    for (const auto& [v, name] : cases) expectUnbiased(r, *scene, v, zSegment(), 50'000, 1800 + i++, name);
    std::vector<Vrl> vrls;
    Rng rng(1810, 0);
    for (int k = 0; k < 24; ++k) vrls.push_back(makeVrl(uniformInCube(rng, 1.0), uniformDirection(rng), 1e-7));
    const LightTree tree = LightTree::build(vrls);
    for (const LightTreeNode& node : tree.nodes()) {
        checkValue(r, node.clusterFlux);
        checkValue(r, node.fluxLength);
    }
    std::vector<CameraSegment> segments = {zSegment()};
    for (int k = 0; k < 3; ++k) segments.push_back(makeSegment(uniformInCube(rng, 1.0), uniformDirection(rng), 2.0));
    checkClusterBounds(r, *scene, tree, segments, 64, 1811);
    checkCutAgainstPlain(r, *scene, tree, segments, 1812, "1e-7 tree");
}

void longVrlCase(CaseResult& r) {
    r.description = "VRLs of length 1e4 passing 0.05 and 1 from the camera segment's middle, sigma_t = 1e-3 and 1, "
                    "vs quadrature; tree of long and short VRLs: bounds, threshold-0 cut";
    int i = 0;
    std::vector<Vrl> vrls;
    for (const double sigmaT : {1e-3, 1.0}) {
        const auto scene = unboundedScene(Rgb(float(0.5 * sigmaT)), Rgb(float(0.5 * sigmaT)), 0.0f);
        for (const double h : {0.05, 1.0}) {
            const V3d dir = V3d(1, 0.3, 0).normalized();
            const Vrl v = makeVrl(V3d(0, h, 1.0) - dir * 5000.0, dir, 1e4);
            expectUnbiased(r, *scene, v, zSegment(), 100'000, 1900 + i++, format("sigma_t %g, h %g", sigmaT, h));
            if (sigmaT == 1.0) vrls.push_back(v);
        }
    }
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.5f), 0.0f);
    Rng rng(1910, 0);
    for (int k = 0; k < 14; ++k) vrls.push_back(makeVrl(uniformInCube(rng, 2.0), uniformDirection(rng), 0.5));
    const LightTree tree = LightTree::build(vrls);
    const std::vector<CameraSegment> segments = {zSegment(), zSegment(1e30), makeSegment(V3d(3, 3, 3), V3d(-1, -1, -1), 6.0)};
    checkClusterBounds(r, *scene, tree, segments, 64, 1911);
    checkCutAgainstPlain(r, *scene, tree, segments, 1912, "long tree");
}

void zeroLengthSegmentCase(CaseResult& r) {
    r.description = "camera segments of length 0, 1e-40 (denormal), 1e-30, 1e-20: VRL, Lightcuts and VPL "
                    "Lightcuts estimates finite, >= 0, exactly 0 at length 0, and below the analytic bound "
                    "(ClusterBound, proportional to the length); lengths 1e-7 and 1e-4 vs quadrature";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const VrlEstimator estimator(*scene, 1);
    Rng rng(2000, 0);
    std::vector<Vrl> vrls, vpls;
    for (int k = 0; k < 32; ++k) {
        vrls.push_back(makeVrl(uniformInCube(rng, 1.0), uniformDirection(rng), 0.5));
        Vrl p = vrls.back();
        p.length = 0.0f;
        vpls.push_back(p);
    }
    const LightTree tree = LightTree::build(vrls);
    const LightTree points = LightTree::build(vpls, LightTreeSettings{2048, 0, true});
    const LightcutsEstimator cut(*scene, tree, estimator, CutSettings{});
    const VplLightcutsEstimator vplCut(*scene, points, CutSettings{});
    const ClusterBound bound(*scene, tree);
    double worstRatio = 0.0;
    for (const float length : {0.0f, 1e-40f, 1e-30f, 1e-20f}) {
        for (int k = 0; k < 4; ++k) {
            CameraSegment seg = makeSegment(uniformInCube(rng, 1.5), uniformDirection(rng), 1.0);
            seg.length = length;
            CutStatistics statistics;
            const Rgb c = cut.estimate(seg, 7 + k, statistics);
            Rng vplRng(2001, uint64_t(k));
            const Rgb p = vplCut.estimate(seg, vplRng, statistics);
            checkValue(r, c);
            checkValue(r, p);
            if (length == 0.0f) {
                require(r, isBlack(c) && isBlack(p), "a zero-length segment must contribute exactly 0");
            }
            for (size_t j = 0; j < vrls.size(); ++j) {
                Rng vr(2002, j);
                const Rgb e = estimator.contribution(vrls[j], seg, vr);
                checkValue(r, e);
                if (length == 0.0f) require(r, isBlack(e), "a zero-length segment must contribute exactly 0");
                bool crosses = false;
                const Rgb b = bound.bound(int32_t(j), seg, &crosses);
                if (crosses) continue;
                ++r.boundChecks;
                if (e.x > b.x || e.y > b.y || e.z > b.z) ++r.boundViolations;
                if (b.x > 0.0f) worstRatio = std::max(worstRatio, double(e.x) / double(b.x));
            }
        }
    }
    compare(r, "largest estimate / analytic bound", worstRatio, 1.0);
    // Short but resolvable segments against the quadrature.
    int i = 0;
    for (const double length : {1e-7, 1e-4}) {
        const CameraSegment seg = makeSegment(V3d(0.1, -0.2, 0.3), V3d(1, 1, 0), length);
        const Vrl v = makeVrl(V3d(0.5, 0.1, 0.2), V3d(0, 1, 1), 0.8);
        expectUnbiased(r, *scene, v, seg, 50'000, 2010 + i++, format("segment length %g", length));
    }
}

// A paired comparison: runs `a` and `b` used the same seeds (scenes that differ
// slightly), so per channel the mean of the per-run differences is tested in its
// own standard errors (t, K - 1 dof), after allowing `relativeAllowance` of b's
// mean (the true difference between the two scenes).
void comparePaired(CaseResult& r, const std::string& label, const ImageStats& a, const ImageStats& b,
                   double relativeAllowance) {
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0, sum2 = 0.0;
        for (size_t i = 0; i < a.runs.size(); ++i) {
            const double d = a.runs[i][c] - b.runs[i][c];
            sum += d;
            sum2 += d * d;
        }
        const double n = double(a.runs.size()), mean = sum / n;
        const double se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1.0));
        compare(r, format("%s, channel %d: paired t (%.5g vs %.5g, SE of the difference %.2g, of either %.2g)",
                          label.c_str(), c, a.mean[c], b.mean[c], se, b.se[c]),
                zScore(a.mean[c], se, b.mean[c], relativeAllowance * std::abs(b.mean[c]) + 1e-30), kImageZ);
    }
}

// Image level, the camera inside a dense medium: a null-bounded cube of half-size
// 1e-3 (10 mean free paths at sigma_t = 1e4, albedo 0.9), the camera 3 mean free
// paths inside its -z face looking out through it, a point light in the vacuum
// 5e-4 beyond the face (so the path tracer's next-event estimation has finite
// variance). Every VRL method against the path tracer (8 runs each).
void denseCameraCase(CaseResult& r) {
    r.description = "camera inside a dense medium (sigma_t = 1e4, albedo 0.9, cube of half-size 1e-3), 3 mean free "
                    "paths from the face it looks out of, point light in the vacuum beyond: vrl, vrl-lightcuts, "
                    "vpl-lightcuts vs the path tracer (8 runs)";
    SceneDescription d;
    d.sensor = test::cameraAtOrigin(4, 4, 70.0f);
    d.sensor.toWorld = Transform::lookAt(Vec3(0.0f, 0.0f, -0.7e-3f), Vec3(0.0f, 0.0f, -1.0f), Vec3(0, 1, 0));
    d.sensor.nearClip = 1e-8f;
    d.sensor.medium = 0;
    d.media.push_back(mediumDescription(Rgb(9e3f), Rgb(1e3f), 0.0f));
    ShapeDescription cube;
    cube.kind = ShapeDescription::Kind::Cube;
    cube.toWorld = Transform::scale(Vec3(1e-3f));
    cube.bsdf = test::nullBsdf();
    cube.interiorMedium = 0;
    d.shapes.push_back(cube);
    EmitterDescription light;
    light.kind = EmitterDescription::Kind::Point;
    light.intensity = Rgb(2.5e-7f);
    light.toWorld = Transform::translate(Vec3(1e-4f, 0.5e-4f, -1.5e-3f));
    d.emitters.push_back(light);
    const auto scene = Scene::build(d);
    const ImageStats reference = renderRuns(r, *scene, methodSettings("path", 1024, 0), 8, 200);
    note(r, format("path: mean %.5g +- %.2g, %.2f s", reference.mean.x, reference.se.x, reference.seconds));
    for (const std::string method : {"vrl", "vrl-lightcuts", "vpl-lightcuts"}) {
        const ImageStats s = renderRuns(r, *scene, methodSettings(method, 16, 4000), 8, 300);
        compareRuns(r, method + " vs path", s, reference);
        note(r, format("%s: mean %.5g +- %.2g, %.2f s", method.c_str(), s.mean.x, s.se.x, s.seconds));
    }
}

SceneDescription cubeWithLightAt(const Vec3& position, int emitterMedium) {
    SceneDescription d = test::mediumOnlyCube(Rgb(0.8f), Rgb(0.2f), 0.0f);
    d.sensor.width = d.sensor.height = 6;
    d.emitters[0].toWorld = Transform::translate(position);
    d.emitters[0].medium = emitterMedium;
    return d;
}

// The point light inside the medium cube (mediumOnlyCube): VRL methods against the
// path tracer. Its next-event estimation from vertices near a point light in a
// medium has infinite variance (weights ~ 1 / d^2), so its standard error is an
// underestimate; 1024 samples per pixel keep that small.
void lightInsideCase(CaseResult& r) {
    r.description = "point light inside a null-bounded medium cube (sigma_s 0.8, sigma_a 0.2), camera outside: vrl, "
                    "vrl-lightcuts, vpl-lightcuts vs the path tracer (8 runs)";
    const auto scene = Scene::build(cubeWithLightAt(Vec3(0.2f, 0.5f, 0.3f), 0));
    const ImageStats reference = renderRuns(r, *scene, methodSettings("path", 1024, 0), 8, 400);
    note(r, format("path: mean %.5g +- %.2g, %.2f s", reference.mean.y, reference.se.y, reference.seconds));
    for (const std::string method : {"vrl", "vrl-lightcuts", "vpl-lightcuts"}) {
        const ImageStats s = renderRuns(r, *scene, methodSettings(method, 16, 4000), 8, 500);
        compareRuns(r, method + " vs path", s, reference);
        note(r, format("%s: mean %.5g +- %.2g, %.2f s", method.c_str(), s.mean.y, s.se.y, s.seconds));
    }
}

// The point light 1e-6 inside / exactly on / 1e-3 outside the cube's top face (y = 1),
// its medium located by the scene, against the same light 1e-3 inside (same seeds:
// a paired comparison per method). Moving the light by 1e-3 changes the image by far
// less than the 1% allowed (the light just outside the face reaches the medium
// through 1e-3 of vacuum instead of medium).
void lightNearBoundaryCase(CaseResult& r, float depth, const char* what) {
    r.description = format("point light %s of a medium cube (medium located by the scene), camera outside: "
                           "every method against the light 1e-3 inside the face, same seeds (paired, 8 runs, 1%% "
                           "allowed for the move)",
                           what);
    const auto scene = Scene::build(cubeWithLightAt(Vec3(0.2f, 1.0f - depth, 0.3f), -1));
    const auto reference = Scene::build(cubeWithLightAt(Vec3(0.2f, 1.0f - 1e-3f, 0.3f), -1));
    note(r, format("emitter medium %d (reference %d)", scene->emitters()[0]->medium, reference->emitters()[0]->medium));
    for (const std::string& method : kAllMethods) {
        const RenderSettings settings = methodSettings(method, method == "path" ? 32 : 2, 2000);
        const ImageStats a = renderRuns(r, *scene, settings, 8, 600);
        const ImageStats b = renderRuns(r, *reference, settings, 8, 600);
        comparePaired(r, method, a, b, 0.01);
    }
}

// ================================================================================================
// Cases: scale invariance
// ================================================================================================

// Media only: the null-bounded cube of mediumOnlyCube (isotropic) with its point
// light and a spot light inside, camera outside.
SceneDescription scaleCubeScene() {
    SceneDescription d = test::mediumOnlyCube(Rgb(0.8f), Rgb(0.2f), 0.0f);
    d.sensor.width = d.sensor.height = 8;
    EmitterDescription spot;
    spot.kind = EmitterDescription::Kind::Spot;
    spot.intensity = Rgb(6.0f, 4.0f, 2.0f);
    spot.cutoffAngle = 40.0f;
    spot.beamWidth = 30.0f;
    spot.medium = 0;
    spot.toWorld = Transform::lookAt(Vec3(-0.4f, 0.7f, -0.2f), Vec3(0.1f, -1.0f, 0.3f), Vec3(0, 0, 1));
    d.emitters.push_back(spot);
    return d;
}

// Surfaces: the lit room with an occluder (spot and area light) plus a point light, isotropic medium.
SceneDescription scaleRoomScene() {
    SceneDescription d = test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f);
    d.sensor.width = d.sensor.height = 8;
    EmitterDescription point;
    point.kind = EmitterDescription::Kind::Point;
    point.intensity = Rgb(2.0f, 3.0f, 4.0f);
    point.toWorld = Transform::translate(Vec3(-1.0f, 0.5f, 1.2f));
    d.emitters.push_back(point);
    return d;
}

// Distances x k, coefficients / k, point and spot intensities x k^2 (area radiance unchanged).
SceneDescription scaled(SceneDescription d, float k) {
    const Transform s = Transform::scale(Vec3(k));
    d.sensor.toWorld = d.sensor.toWorld.then(s);
    d.sensor.nearClip *= k;
    d.sensor.farClip *= k;
    for (auto& m : d.media) {
        m.sigmaS /= k;
        m.sigmaA /= k;
    }
    for (auto& shape : d.shapes) {
        shape.toWorld = shape.toWorld.then(s);
        shape.center *= k;
        shape.radius *= k;
    }
    for (auto& e : d.emitters) {
        e.toWorld = e.toWorld.then(s);
        e.intensity *= k * k;
    }
    return d;
}

// Renders with the same seeds at scale 1 and k: a paired t on the image means per
// channel, allowing 1e-4 relative (float rounding of the scaled scene). Identical
// seeds keep the two images close wherever the arithmetic is scale-invariant, so the
// test detects changes far below the noise of either image; where the images
// decorrelate the paired SE grows to about that noise, and the sample counts keep
// it near 1% of the mean.
void scaleCase(CaseResult& r, const std::string& method, float k, bool room) {
    r.description = format("scale invariance, %s: %s scaled by %g against scale 1 (distances x k, coefficients "
                           "/ k, point and spot intensities x k^2), same seeds, 8 runs, paired t on the image means",
                           method.c_str(),
                           room ? "the lit room (occluder, spot, point and area light)"
                                : "the medium-only cube (point and spot light inside)",
                           k);
    const SceneDescription d = room ? scaleRoomScene() : scaleCubeScene();
    const auto base = Scene::build(d);
    const auto other = Scene::build(scaled(d, k));
    RenderSettings settings = methodSettings(method, method == "path" ? 128 : 2, 1500);
    const ImageStats a = renderRuns(r, *base, settings, 8, 700);
    const ImageStats b = renderRuns(r, *other, settings, 8, 700);
    comparePaired(r, format("scale %g vs 1", k), b, a, 1e-4);
    note(r, format("relative difference of the image means (green) %.3g; %.2f s + %.2f s",
                   relativeDifference(a.mean.y, b.mean.y), a.seconds, b.seconds));
}

// Surface offsets below unit scale (they were absolute, 1e-4 units: twice the gap
// between the ceiling and the area light here; now relative to the hit
// triangle's coordinates): the lit room scaled by 1e-3, the camera looking at the
// ceiling around the area light, direct light and single scattering only
// (maxDepth 2), path tracer; paired against scale 1.
void smallRoomCase(CaseResult& r) {
    r.description = "scale invariance with surfaces below unit scale: the lit room scaled by 1e-3, camera looking at "
                    "the ceiling around the area light (maxDepth 2), path tracer, paired t against scale 1 (8 runs)";
    SceneDescription d = scaleRoomScene();
    d.sensor.toWorld = Transform::lookAt(Vec3(-0.8f, 1.2f, -0.4f), Vec3(-0.8f, 2.0f, 0.3f), Vec3(0, 0, 1));
    const auto base = Scene::build(d);
    const auto other = Scene::build(scaled(d, 1e-3f));
    RenderSettings settings = methodSettings("path", 64, 0);
    settings.maxDepth = 2;
    const ImageStats a = renderRuns(r, *base, settings, 8, 900);
    const ImageStats b = renderRuns(r, *other, settings, 8, 900);
    comparePaired(r, "scale 0.001 vs 1", b, a, 1e-4);
    note(r, format("relative difference of the image means (green) %.3g", relativeDifference(a.mean.y, b.mean.y)));
}

// ================================================================================================
// Cases: light tree extremes
// ================================================================================================

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

// ================================================================================================
// Cases: chromatic image
// ================================================================================================

void chromaticFurnaceCase(CaseResult& r) {
    r.description = "furnace with a chromatic non-absorbing medium sigma_s = (1e-4, 1e-2, 1) (channels differ by "
                    "1e4; spectral tracking with null collisions in light tracing): every method against 1 per "
                    "channel (8 runs)";
    furnaceAllMethods(r, Rgb(1e-4f, 1e-2f, 1.0f), Rgb(0.0f), 0.0f, 0.0, 8, 1024, 16, 8000);
}

void chromaticImageCase(CaseResult& r) {
    r.description = "medium cube with sigma_t = (1e-2, 1, 1e2), albedo 0.5, point light inside, camera outside: "
                    "vrl, vrl-lightcuts, vpl-lightcuts vs the path tracer per channel (8 runs)";
    SceneDescription d = test::mediumOnlyCube(Rgb(0.5e-2f, 0.5f, 50.0f), Rgb(0.5e-2f, 0.5f, 50.0f), 0.0f);
    d.sensor.width = d.sensor.height = 6;
    const auto scene = Scene::build(d);
    const ImageStats reference = renderRuns(r, *scene, methodSettings("path", 1024, 0), 8, 700);
    note(r, format("path: mean (%.4g %.4g %.4g), %.2f s", reference.mean.x, reference.mean.y, reference.mean.z,
                   reference.seconds));
    for (const std::string method : {"vrl", "vrl-lightcuts", "vpl-lightcuts"}) {
        const ImageStats s = renderRuns(r, *scene, methodSettings(method, 16, 1000), 8, 800);
        compareRuns(r, method + " vs path", s, reference);
        note(r, format("%s: mean (%.4g %.4g %.4g) +- (%.2g %.2g %.2g), %.2f s", method.c_str(), s.mean.x, s.mean.y,
                       s.mean.z, s.se.x, s.se.y, s.se.z, s.seconds));
    }
}

std::vector<StiffCase> makeCases() {
    std::vector<StiffCase> cases;
    const auto add = [&](const std::string& group, const std::string& name, std::function<void(CaseResult&)> f) {
        cases.push_back({group, name, [f](CaseResult& r, const CaseOptions&) { f(r); }, ""});
    };
    for (const double sigmaT : {1e-6, 1e-2, 1.0, 1e2, 1e4})
        add("media", format("sigma_t = %g (estimator)", sigmaT), [sigmaT](CaseResult& r) { sigmaTCase(r, sigmaT); });
    for (const double albedo : {0.0, 0.9999})
        add("media", format("albedo %g (estimator)", albedo), [albedo](CaseResult& r) { albedoCase(r, albedo); });
    for (const float g : {-0.99f, 0.99f})
        add("media", format("HG g = %g (estimator)", g), [g](CaseResult& r) { hgCase(r, g); });
    add("media", "chromatic 1e4 (estimator)", chromaticEstimatorCase);
    add("media", "furnace sigma_t = 1e-6", [](CaseResult& r) {
        furnaceCase(r, Rgb(1e-6f), Rgb(0.0f), 0.0f, 0.0, "sigma_s = 1e-6 (optically very thin)", 50);
    });
    add("media", "furnace sigma_t = 1", [](CaseResult& r) {
        furnaceCase(r, Rgb(1.0f), Rgb(0.0f), 0.0f, 0.0, "sigma_s = 1, isotropic");
    });
    add("media", "furnace albedo 0.9999", [](CaseResult& r) {
        furnaceCase(r, Rgb(0.9999f), Rgb(1e-4f), 0.0f, 1e-3,
                    "sigma_t = 1, albedo 0.9999 (absorption lowers L by <= (1 - albedo) E[collisions] < 1e-3)");
    });
    for (const float g : {-0.7f, 0.7f})
        add("media", format("furnace HG g = %g", g), [g](CaseResult& r) {
            furnaceCase(r, Rgb(1.0f), Rgb(0.0f), g, 0.0, format("sigma_s = 1, HG g = %g", g).c_str());
        });
    for (const float g : {-0.99f, 0.99f})
        add("media", format("HG g = %g (image)", g), [g](CaseResult& r) { hgImageCase(r, g); });
    add("media", "furnace albedo 0 (absorber)", absorbingFurnaceCase);
    add("media", "chromatic 1e4 furnace", chromaticFurnaceCase);
    add("media", "chromatic 1e4 cube (image)", chromaticImageCase);

    add("geometry", "parallel", parallelCase);
    add("geometry", "crossing", crossingCase);
    add("geometry", "touching", touchingCase);
    add("geometry", "collinear", collinearCase);
    add("geometry", "VRL length 1e-7", shortVrlCase);
    add("geometry", "VRL length 1e4", longVrlCase);
    add("geometry", "zero-length camera segment", zeroLengthSegmentCase);
    add("geometry", "camera inside dense medium", denseCameraCase);
    add("geometry", "light inside the medium", lightInsideCase);
    add("geometry", "light 1e-6 inside the boundary",
        [](CaseResult& r) { lightNearBoundaryCase(r, 1e-6f, "1e-6 inside the top face"); });
    add("geometry", "light on the boundary",
        [](CaseResult& r) { lightNearBoundaryCase(r, 0.0f, "exactly on the top face"); });
    add("geometry", "light 1e-3 outside the boundary",
        [](CaseResult& r) { lightNearBoundaryCase(r, -1e-3f, "1e-3 outside the top face (in the vacuum)"); });

    for (const std::string method : {"path", "vrl", "vrl-lightcuts", "vpl-lightcuts"})
        for (const float k : {1e-3f, 1e3f})
            add("scale", format("cube, %s, k = %g", method.c_str(), k),
                [method, k](CaseResult& r) { scaleCase(r, method, k, false); });
    for (const std::string method : {"path", "vrl", "vrl-lightcuts", "vpl-lightcuts"})
        add("scale", format("room, %s, k = 1000", method.c_str()),
            [method](CaseResult& r) { scaleCase(r, method, 1e3f, true); });
    cases.push_back({"scale", "room, ceiling by the area light, k = 0.001",
                     [](CaseResult& r, const CaseOptions&) { smallRoomCase(r); }});

    add("tree", "one VRL", oneVrlCase);
    add("tree", "identical VRLs", identicalVrlsCase);
    add("tree", "collinear VRLs", collinearVrlsCase);
    cases.push_back({"tree", "many VRLs", manyVrlsCase, ""});
    add("tree", "fluxes 1e-30 .. 1e30", fluxRangeCase);
    return cases;
}

std::string escapeCell(std::string s) {
    std::string out;
    for (char c : s) {
        if (c == '|') out += "\\|";
        else if (c == '\n') out += ' ';
        else out += c;
    }
    return out;
}

std::string shortNumber(double v) {
    if (v == 0.0) return "0";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    if (std::isnan(v)) return "NaN";
    return format("%.3g", v);
}

}  // namespace

const std::vector<StiffCase>& stiffCases() {
    static const std::vector<StiffCase> cases = makeCases();
    return cases;
}

CaseResult runCase(const StiffCase& stiffCase, const CaseOptions& options) {
    CaseResult r;
    r.group = stiffCase.group;
    r.name = stiffCase.name;
    r.knownIssue = stiffCase.knownIssue;
    const auto start = std::chrono::steady_clock::now();
    try {
        stiffCase.run(r, options);
    } catch (const std::exception& e) {
        fail(r, std::string("exception: ") + e.what());
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    bool ok = r.finite && r.nonNegative && r.failures.empty();
    for (const Comparison& c : r.comparisons) ok = ok && c.ok();
    if (r.boundAsserted && r.boundViolations > 0) ok = false;
    r.passed = ok;
    return r;
}

std::string summary(const CaseResult& r) {
    std::ostringstream s;
    s << "[" << r.group << "] " << r.name << ": " << (r.passed ? "pass" : r.knownIssue.empty() ? "FAIL" : "FAIL (known issue)") << " in " << format("%.2f", r.seconds)
      << " s; " << r.valuesChecked << " values (" << (r.finite ? "finite" : "NON-FINITE") << ", "
      << (r.nonNegative ? ">= 0" : "NEGATIVE") << "); " << r.comparisons.size() << " comparisons";
    if (const Comparison* w = r.worst()) s << ", worst: " << w->label << " = " << shortNumber(w->value) << " vs " << shortNumber(w->tolerance);
    s << "; bound " << r.boundViolations << "/" << r.boundChecks << (r.boundAsserted ? " (asserted)" : " (reported)");
    for (const Comparison& c : r.comparisons)
        if (!c.ok()) s << "\n    failed: " << c.label << " = " << shortNumber(c.value) << " > " << shortNumber(c.tolerance);
    for (const std::string& f : r.failures) s << "\n    failure: " << f;
    if (!r.notes.empty()) s << "\n    notes: " << r.notes;
    return s.str();
}

std::string markdownTable(const std::vector<CaseResult>& results, const std::string& preamble) {
    std::ostringstream md;
    md << "# Stiff cases\n\n" << preamble << "\n\n";
    md << "| group | case | checks | agreement (value vs tolerance) | result | time |\n";
    md << "|---|---|---|---|---|---|\n";
    double total = 0.0;
    int passed = 0;
    for (const CaseResult& r : results) {
        std::ostringstream checks;
        checks << r.valuesChecked << " values " << (r.finite ? "finite" : "**not finite**") << ", "
               << (r.nonNegative ? "none < 0" : "**some < 0**") << "; " << r.comparisons.size() << " comparisons";
        if (r.boundChecks > 0)
            checks << "; bound >= estimate " << (r.boundAsserted ? "" : "(heuristic, reported) ") << "on "
                   << r.boundChecks << " samples, " << r.boundViolations << " exceeded";
        std::string agreement = "-";
        if (const Comparison* w = r.worst())
            agreement = escapeCell(w->label) + ": " + shortNumber(w->value) + " vs " + shortNumber(w->tolerance);
        const std::string result = r.passed ? (r.knownIssue.empty() ? "pass" : "pass (known issue not reproduced)")
                                            : (r.knownIssue.empty() ? "**FAIL**" : "**FAIL** (known issue)");
        md << "| " << r.group << " | " << escapeCell(r.name) << " | " << checks.str() << " | " << agreement << " | "
           << result << " | " << format("%.2f s", r.seconds) << " |\n";
        total += r.seconds;
        passed += r.passed;
    }
    int known = 0;
    for (const CaseResult& r : results) known += !r.passed && !r.knownIssue.empty();
    md << "\n" << passed << " of " << results.size() << " cases pass";
    if (known) md << ", " << known << " fail" << (known > 1 ? "" : "s") << " on a known issue (below)";
    md << "; " << format("%.1f", total) << " s in all.\n\n";
    md << "## Cases\n\n";
    for (const CaseResult& r : results) {
        md << "- **" << r.group << " / " << escapeCell(r.name) << "**: " << escapeCell(r.description) << ".";
        if (!r.knownIssue.empty()) md << " Known issue: " << escapeCell(r.knownIssue) << ".";
        if (!r.notes.empty()) md << " Notes: " << escapeCell(r.notes) << ".";
        for (const Comparison& c : r.comparisons)
            if (!c.ok()) md << " Failed: " << escapeCell(c.label) << " = " << shortNumber(c.value) << " > " << shortNumber(c.tolerance) << ".";
        for (const std::string& f : r.failures) md << " Failure: " << escapeCell(f) << ".";
        md << "\n";
    }
    return md.str();
}

}  // namespace vrl::stiff
