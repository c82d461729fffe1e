// Helpers shared by the stiff cases (stiff_cases.h; one source per group:
// stiff_media_cases.cpp, stiff_geometry_cases.cpp, stiff_scale_cases.cpp,
// stiff_tree_cases.cpp). Conventions used throughout:
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
#pragma once

#include "render/core/rng.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/renderer.h"
#include "render/scene/scene.h"
#include "render/vrl/vrl_estimator.h"
#include "tests/render/stiff/stiff_cases.h"

#include <Imath/ImathVec.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace vrl::stiff {

using V3d = Imath::V3d;
inline constexpr double kPiD = 3.14159265358979323846;
inline constexpr double kInfD = std::numeric_limits<double>::infinity();
inline constexpr double kZ = 4.5;       // estimator-level z tolerance (see the file comment)
inline constexpr double kImageZ = 6.0;  // image-level t tolerance over K = 8 runs (see the file comment)

inline V3d toD(const Vec3& v) { return {v.x, v.y, v.z}; }
inline Vec3 toF(const V3d& v) { return Vec3(float(v.x), float(v.y), float(v.z)); }

// printf-style formatting into a std::string (at most 1023 characters).
std::string format(const char* f, ...);

// A case that ignores CaseOptions (every case but the many-VRL one).
StiffCase makeCase(const std::string& group, const std::string& name, std::function<void(CaseResult&)> run);

// ---- Result helpers ------------------------------------------------------------

// Counts a value into valuesChecked, clearing `finite` / `nonNegative` as needed.
void checkValue(CaseResult& r, double v);
void checkValue(CaseResult& r, const Rgb& c);
void fail(CaseResult& r, const std::string& message);  // keeps the first 20
void require(CaseResult& r, bool ok, const std::string& message);
void compare(CaseResult& r, const std::string& label, double value, double tolerance);
void note(CaseResult& r, const std::string& text);

// |mean - reference| in standard errors after allowing `allowance` (absolute).
double zScore(double mean, double se, double reference, double allowance);

// Recursive float summation of n terms: relative error up to about n 2^-24 (with a
// factor 4 of headroom), never below the 1e-4 lightcuts_test uses for images.
double accumulationTolerance(size_t n);

double relativeDifference(double a, double b);

// ---- Scenes ----------------------------------------------------------------------

MediumDescription mediumDescription(const Rgb& sigmaS, const Rgb& sigmaA, float g);

// One unbounded medium, no shapes (visibility 1, convex): the estimator-level cases.
std::unique_ptr<Scene> unboundedScene(const Rgb& sigmaS, const Rgb& sigmaA, float g);

// ---- Reference quadrature (double precision, independent of vrl_estimator.cpp) ----
//   L = Tb Phi sigma_s^2 int_0^S int_0^t fV(d, n) fU(n, -w) e^{-sigma_t (u + |x_u - x_v|)} / |x_u - x_v|^2 dv du,
// with u = delta + h tan(theta) (du / w^2 = dtheta / h) and v = v0 + h0 sinh(alpha) / sinT
// around the lines' closest approach (dv / h = dalpha / sinT): smooth integrands
// unless the lines cross inside both segments.

struct MediumParams {
    V3d sigmaS, sigmaT;
    double g = 0.0;
};
MediumParams paramsOf(const HomogeneousMedium& m);

double hg(double g, double cosine);  // Henyey-Greenstein (isotropic at g = 0), per steradian

// Gauss-Legendre quadrature of f over [lo, hi]: `panels` panels of 8 nodes.
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

struct Reference {
    V3d value;
    double relativeError = 0.0;  // change at the last panel doubling, relative to the largest channel
};

// Doubles the panels (16 .. 256, i.e. 128 .. 2048 nodes per variable) until the
// value changes by less than 1e-6 of its largest channel.
Reference reference(const Vrl& vrl, const CameraSegment& seg, const MediumParams& m);

// ---- Estimator sampling -------------------------------------------------------------

struct SampleStats {
    V3d mean{0.0}, se{0.0};
    double maxSample = 0.0;
};

// n estimates from the stream (seed, 0), each checked for finiteness and sign.
SampleStats sampleEstimator(CaseResult& r, const VrlEstimator& estimator, const Vrl& vrl, const CameraSegment& seg,
                            int n, uint64_t seed);

// Estimator mean against the quadrature, per channel. The allowance is the
// quadrature's convergence (x 10, at least 1e-5 relative) plus 1e-35 absolute
// (float underflow of channels that are ~0).
void expectUnbiased(CaseResult& r, const Scene& scene, const Vrl& vrl, const CameraSegment& seg, int n,
                    uint64_t seed, const std::string& label);

Vrl makeVrl(const V3d& origin, const V3d& direction, double length, const Rgb& flux = Rgb(1.0f), int medium = 0);
CameraSegment makeSegment(const V3d& origin, const V3d& direction, double length, const Rgb& before = Rgb(1.0f),
                          int medium = 0);

V3d uniformDirection(Rng& rng);
V3d uniformInCube(Rng& rng, double half);

struct Pair {
    Vrl vrl;
    CameraSegment seg;
};

// `count` random (VRL, segment) pairs at geometric scale `scale` (origins in the
// cube of half-size scale, VRL lengths 0.2 .. 1.5 scale, camera lengths 0.5 .. 3
// scale), from the stream (seed, 0).
std::vector<Pair> randomPairs(int count, double scale, uint64_t seed, const Rgb& flux = Rgb(1.0f));

// The camera segment from the origin along +z (throughput 0.9 before it).
inline const V3d kZ3(0, 0, 1);
CameraSegment zSegment(double length = 2.0);

// ---- Light-tree checks ---------------------------------------------------------------------

bool allIsotropic(const Scene& scene);

// Every node of `tree` against every segment: a crossing line gives an infinite
// bound; otherwise `samples` estimates of the node (its representative carrying the
// cluster flux, as the cut evaluates it) must not exceed the bound in any channel.
// Counted into boundChecks / boundViolations (asserted: the default bound is proven in HG media too).
void checkClusterBounds(CaseResult& r, const Scene& scene, const LightTree& tree,
                        const std::vector<CameraSegment>& segments, int samples, uint64_t seed);

// Lightcuts at threshold 0 (no cut-size limit) against the plain sum over the
// tree's VRLs with the same streams: equal up to float accumulation (the cut adds
// and subtracts inner-node estimates); tolerance accumulationTolerance(N) of the
// largest channel of the plain sum. (Nodes whose bound is
// exactly 0 stay unrefined even at threshold 0: their VRLs contribute exactly 0.)
// Also runs the default threshold 0.02 and checks its result's sign and finiteness.
void checkCutAgainstPlain(CaseResult& r, const Scene& scene, const LightTree& tree,
                          const std::vector<CameraSegment>& segments, uint64_t streamBase, const std::string& label,
                          double tolerance = -1.0);

// ---- Image-level helpers ---------------------------------------------------------------------

struct ImageStats {
    V3d mean{0.0}, se{0.0};  // over runs of the image mean (per channel)
    std::vector<V3d> runs;
    double seconds = 0.0;
};

// `runs` renders with seeds seedBase + run. Every pixel of the image and of each
// transport layer must be finite and >= 0 (the cut statistics layers too); the
// bound counters of Lightcuts renders go into the case (isotropic: asserted).
ImageStats renderRuns(CaseResult& r, const Scene& scene, RenderSettings settings, int runs, uint64_t seedBase);

// Two independent sets of runs: per channel |difference| in combined standard errors.
void compareRuns(CaseResult& r, const std::string& label, const ImageStats& a, const ImageStats& b,
                 double relativeAllowance = 0.0);

// Runs against an analytic value per channel.
void compareAnalytic(CaseResult& r, const std::string& label, const ImageStats& a, const V3d& expected,
                     double relativeAllowance);

// A paired comparison: runs `a` and `b` used the same seeds (scenes that differ
// slightly), so per channel the mean of the per-run differences is tested in its
// own standard errors (t, K - 1 dof), after allowing `relativeAllowance` of b's
// mean (the true difference between the two scenes).
void comparePaired(CaseResult& r, const std::string& label, const ImageStats& a, const ImageStats& b,
                   double relativeAllowance);

// Settings for `method` ("path", "vrl", "vrl-lightcuts", "vpl-lightcuts", ...), tiles of 4 pixels.
RenderSettings methodSettings(const std::string& method, int spp, uint64_t vrls);

// A closed sphere of radius `radius` around the camera emitting `radiance` inwards,
// black walls, filled with medium (sigmaS, sigmaA, g). Non-absorbing: every pixel's
// expected radiance is exactly `radiance` (each camera path ends on the wall);
// pure absorber: radiance exp(-sigma_t t), t the distance to the (tessellated) wall.
SceneDescription furnace(const Rgb& radiance, const Rgb& sigmaS, const Rgb& sigmaA, float g, int side = 4);

inline const std::vector<std::string> kAllMethods = {"path", "vrl", "vrl-lightcuts", "vpl-lightcuts"};

// The furnace: every method's image mean (K runs) against radiance 1 per channel,
// allowing `bias` (relative) for media that absorb a little.
void furnaceAllMethods(CaseResult& r, const Rgb& sigmaS, const Rgb& sigmaA, float g, double bias, int runs,
                       int pathSpp, int vrlSpp, uint64_t vrls);

}  // namespace vrl::stiff
