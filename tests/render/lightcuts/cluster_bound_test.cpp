// Tests of ClusterBound (Vibert et al. 2019 §4, Eq. 8-11): the upper bound on a
// light-tree node's single-sample VRL estimate that drives cut refinement.
//
// 1. Geometry helpers against brute force written here in double precision:
//    maxSubtendedAngle against a scan over foot positions, distanceLineBox and
//    distanceLineSegment against golden-section searches of convex functions.
// 2. The bound bounds the estimate (isotropic media): random light trees built
//    with LightTree::build around a reference camera line (generic, zero-length,
//    parallel, near-parallel, coplanar and nearly crossing VRLs), every node of
//    each tree against random camera segments (lengths up to 1e4), one sample
//    each, evaluated exactly as the cut does (the representative VRL carrying
//    the cluster flux, VrlEstimator(scene, 1)). Every channel must stay below the
//    bound: this is a deterministic inequality (up to the bound's own 1.001
//    rounding margin), so zero violations are required, and the largest ratio
//    estimate / bound is printed (near-tight cases, a VRL parallel to a
//    segment with its foot points inside it, come within ~1e-3 of 1). Media:
//    unbounded with and without absorption, the convex cube, two media, and
//    coordinates far from the origin; plus a deterministic tight case (parallel
//    VRL) for segment lengths up to 1e30 and the exactly crossing case.
// 3. Henyey-Greenstein media. The proven cone bound (HgBound::Cones, the
//    default): zero violations over ~1e6 triples for each g in {-0.9, -0.5, 0.3,
//    0.7, 0.9, 0.99}, chromatic coefficients, the degenerate VRLs above, and
//    nodes spanning two media of different g; it equals the isotropic bound's
//    structure (same tree, same segment) times a phase factor between
//    min f^2 and max f^2 / w. The paper's heuristic (HgBound::Epsilon): the
//    bound x (1 + epsilon); its violation rate is printed and only capped
//    loosely; the factor itself is checked exactly.
// 4. Exact minimum distances for small nodes.
//
// All streams have fixed seeds; sample counts are stated with each test.
#include "render/lightcuts/bounds/cluster_bound.h"

#include "render/core/rng.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/scene/scene.h"
#include "render/vrl/vrl_estimator.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace vrl {
namespace {

using V3d = Imath::V3d;
constexpr double kPiD = 3.14159265358979323846;

V3d toD(const Vec3& v) { return {v.x, v.y, v.z}; }
Vec3 toF(const V3d& v) { return Vec3(float(v.x), float(v.y), float(v.z)); }

// ---- Random helpers -----------------------------------------------------------

double uniform(Rng& rng, double lo, double hi) { return lo + (hi - lo) * rng.nextDouble(); }
double logUniform(Rng& rng, double lo, double hi) { return lo * std::pow(hi / lo, rng.nextDouble()); }
V3d uniformDirection(Rng& rng) {
    const double z = uniform(rng, -1.0, 1.0), phi = uniform(rng, 0.0, 2.0 * kPiD);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
}
V3d uniformInBox(Rng& rng, const V3d& centre, double halfSize) {
    return centre + V3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)) * halfSize;
}
// A unit vector orthogonal to unit w.
V3d orthogonal(const V3d& w) {
    const V3d a = std::abs(w.x) < 0.6 ? V3d(1, 0, 0) : V3d(0, 1, 0);
    return (a - w * w.dot(a)).normalized();
}
Vec3 unitF(const V3d& d) { return toF(d.normalized()).normalized(); }

// ---- Brute force ---------------------------------------------------------------

// Minimum of a convex function on [lo, hi] (golden-section search, endpoints included).
template <class F>
double goldenMinimum(F f, double lo, double hi) {
    const double r = 0.5 * (std::sqrt(5.0) - 1.0);
    double a = lo, b = hi, c = b - r * (b - a), d = a + r * (b - a);
    double fc = f(c), fd = f(d);
    for (int i = 0; i < 200 && b - a > 0.0; ++i) {
        if (fc <= fd) {
            b = d, d = c, fd = fc, c = b - r * (b - a), fc = f(c);
        } else {
            a = c, c = d, fc = fd, d = a + r * (b - a), fd = f(d);
        }
    }
    return std::min({fc, fd, f(lo), f(hi), f(0.5 * (a + b))});
}

double distancePointBox(const V3d& p, const Imath::Box3f& box) {
    V3d q;
    for (int i = 0; i < 3; ++i) q[i] = std::clamp(p[i], double(box.min[i]), double(box.max[i]));
    return (p - q).length();
}
double distancePointLine(const V3d& p, const V3d& origin, const V3d& unitDirection) {
    const V3d r = p - origin;
    return (r - unitDirection * unitDirection.dot(r)).length();
}

// Brute-force line-box distance: the distance from o + t d to the box is convex in t and
// its minimiser lies within the box's half diagonal of the projection of its centre.
double bruteLineBox(const Vec3& origin, const Vec3& direction, const Imath::Box3f& box) {
    const V3d o = toD(origin), d = toD(direction).normalized();
    const V3d centre = (toD(box.min) + toD(box.max)) * 0.5;
    const double radius = 0.5 * (toD(box.max) - toD(box.min)).length();
    const double tc = d.dot(centre - o);
    return goldenMinimum([&](double t) { return distancePointBox(o + d * t, box); }, tc - radius - 1.0,
                         tc + radius + 1.0);
}
// Brute-force line-segment distance: convex in the segment parameter.
double bruteLineSegment(const Vec3& origin, const Vec3& direction, const Vec3& a, const Vec3& b) {
    const V3d o = toD(origin), d = toD(direction).normalized(), pa = toD(a), pb = toD(b);
    return goldenMinimum([&](double s) { return distancePointLine(pa + (pb - pa) * s, o, d); }, 0.0, 1.0);
}

// ---- 1. Geometry helpers -----------------------------------------------------------

// Scan of the subtended angle over foot positions Delta in [-S/2, 3S/2] (the maximum
// is inside [0, S]); 2e5 steps, the scan's error at a smooth maximum is O(step^2).
TEST(ClusterBoundGeometry, MaxSubtendedAngleMatchesBruteForceScan) {
    for (double s : {1e-3, 0.1, 1.0, 3.7, 50.0, 1e3}) {
        for (double h : {1e-3, 0.05, 1.0, 2.5, 40.0, 1e3}) {
            constexpr int kSteps = 200'000;
            double best = -1.0;
            for (int i = 0; i <= kSteps; ++i) {
                const double delta = -0.5 * s + 2.0 * s * (i + 0.37) / kSteps;  // offset: not exactly S/2
                best = std::max(best, std::atan((s - delta) / h) - std::atan(-delta / h));
            }
            EXPECT_NEAR(maxSubtendedAngle(s, h), best, 1e-7 * (1.0 + best)) << "S=" << s << " h=" << h;
            EXPECT_GE(maxSubtendedAngle(s, h), best - 1e-12) << "must be an upper bound, S=" << s << " h=" << h;
        }
    }
}

TEST(ClusterBoundGeometry, MaxSubtendedAngleLimits) {
    // S -> infinity: pi; h -> infinity: 0 (like S / h); h = 0: pi.
    EXPECT_NEAR(maxSubtendedAngle(1e9, 1.0), kPiD, 1e-8);
    EXPECT_NEAR(maxSubtendedAngle(1e4, 1e-3), kPiD, 1e-6);
    EXPECT_LT(maxSubtendedAngle(1.0, 1e9), 1e-8);
    EXPECT_NEAR(maxSubtendedAngle(1.0, 1e6) / (1.0 / 1e6), 1.0, 1e-9);
    EXPECT_DOUBLE_EQ(maxSubtendedAngle(1.0, 0.0), kPiD);
    // Monotone: increasing in S, decreasing in h, always in [0, pi].
    double previous = 0.0;
    for (double s = 1e-4; s < 1e6; s *= 1.7) {
        const double theta = maxSubtendedAngle(s, 0.3);
        EXPECT_GE(theta, previous);
        EXPECT_LE(theta, kPiD);
        previous = theta;
    }
    previous = kPiD;
    for (double h = 1e-4; h < 1e6; h *= 1.7) {
        const double theta = maxSubtendedAngle(2.0, h);
        EXPECT_LE(theta, previous);
        EXPECT_GE(theta, 0.0);
        previous = theta;
    }
}

// 1000 random lines and boxes (seed 11), including flat boxes and axis-parallel and
// in-plane directions. Tolerance 1e-5 x (1 + scale): directions are float unit vectors
// (|d|^2 = 1 +- 1e-7) and the function assumes unit length.
TEST(ClusterBoundGeometry, DistanceLineBoxMatchesBruteForce) {
    Rng rng(11, 0);
    int crossing = 0;
    for (int i = 0; i < 1000; ++i) {
        const V3d centre = uniformInBox(rng, V3d(0.0), 5.0);
        V3d half(logUniform(rng, 1e-3, 3.0), logUniform(rng, 1e-3, 3.0), logUniform(rng, 1e-3, 3.0));
        if (i % 20 == 0) half[i / 20 % 3] = 0.0;  // flat box
        const Imath::Box3f box(toF(centre - half), toF(centre + half));
        const V3d origin = uniformInBox(rng, V3d(0.0), 10.0);
        V3d d = uniformDirection(rng);
        if (i % 3 == 0)  // aimed near the box: crossing, grazing or just missing
            d = (uniformInBox(rng, centre, 1.2 * std::max({half.x, half.y, half.z})) - origin).normalized();
        if (i % 10 == 1) d = V3d(0.0), d[i / 10 % 3] = (i % 20 == 1) ? 1.0 : -1.0;  // axis-parallel
        if (i % 10 == 2) d[i / 10 % 3] = 0.0;                                       // in a coordinate plane
        const Vec3 direction = unitF(d);
        const double expected = bruteLineBox(toF(origin), direction, box);
        const double got = distanceLineBox(toF(origin), direction, box);
        const double scale = 1.0 + (origin - centre).length() + half.length();
        EXPECT_NEAR(got, expected, 1e-5 * scale) << "case " << i;
        crossing += got == 0.0;
    }
    std::printf("[ distanceLineBox ] 1000 random cases, %d crossing the box\n", crossing);
    EXPECT_GT(crossing, 20);  // the crossing branch was exercised
}

// The *infinite* line: lines through a box return exactly 0, also when the given
// origin lies far beyond the box at either end (seed 12, 500 lines).
TEST(ClusterBoundGeometry, DistanceLineBoxIsZeroWhenTheInfiniteLineCrosses) {
    Rng rng(12, 0);
    for (int i = 0; i < 500; ++i) {
        const V3d centre = uniformInBox(rng, V3d(0.0), 5.0);
        const V3d half(logUniform(rng, 1e-2, 3.0), logUniform(rng, 1e-2, 3.0), logUniform(rng, 1e-2, 3.0));
        const Imath::Box3f box(toF(centre - half), toF(centre + half));
        // A point in the central half of the box, and a direction (axis-parallel for some).
        const V3d inside = centre + V3d(uniform(rng, -0.5, 0.5) * half.x, uniform(rng, -0.5, 0.5) * half.y,
                                        uniform(rng, -0.5, 0.5) * half.z);
        V3d d = uniformDirection(rng);
        if (i % 5 == 0) d = V3d(0.0), d[i % 3] = 1.0;
        const Vec3 direction = unitF(d);
        for (double t : {0.0, 50.0, -50.0, 1e3, -1e3}) {  // the segment before, after, or around the box
            const Vec3 origin = toF(inside - toD(direction) * t);
            EXPECT_EQ(distanceLineBox(origin, direction, box), 0.0) << "case " << i << " t=" << t;
        }
    }
    // An empty box is infinitely far.
    EXPECT_TRUE(std::isinf(distanceLineBox(Vec3(0.0f), Vec3(1, 0, 0), Imath::Box3f())));
}

// Axis-parallel lines have the 2D point-rectangle distance in the other two axes as
// their exact distance; lines in a face's plane touch the box (distance 0).
TEST(ClusterBoundGeometry, DistanceLineBoxAxisParallelDirections) {
    const Imath::Box3f box(Vec3(-1.0f, -2.0f, 0.5f), Vec3(1.0f, 3.0f, 1.5f));
    Rng rng(13, 0);
    for (int i = 0; i < 300; ++i) {
        const int axis = i % 3;
        const V3d origin = uniformInBox(rng, V3d(0.0), 6.0);
        for (double sign : {1.0, -1.0}) {
            V3d d(0.0);
            d[axis] = sign;
            double expected2 = 0.0;
            for (int k = 0; k < 3; ++k) {
                if (k == axis) continue;
                const double o = float(origin[k]);
                const double gap = std::max({double(box.min[k]) - o, o - double(box.max[k]), 0.0});
                expected2 += gap * gap;
            }
            EXPECT_NEAR(distanceLineBox(toF(origin), toF(d), box), std::sqrt(expected2), 1e-6) << "case " << i;
        }
    }
    // In the plane of a face (d == 0 branch with o exactly on min/max): touching.
    EXPECT_EQ(distanceLineBox(Vec3(5.0f, -2.0f, 1.0f), Vec3(1, 0, 0), box), 0.0);
    EXPECT_EQ(distanceLineBox(Vec3(1.0f, 3.0f, -7.0f), Vec3(0, 0, 1), box), 0.0);
    // Along an edge's line but one float step outside: 0 or the exact 2^-23, never more
    // (distanceLineSegment subtracts in float first; rounding towards 0 is the safe side).
    EXPECT_LE(distanceLineBox(Vec3(std::nextafter(1.0f, 2.0f), 3.0f, -7.0f), Vec3(0, 0, 1), box), 0x1p-23 * 1.0000001);
}

// 1000 random segments (seed 14): generic, parallel and antiparallel to the line,
// zero length, and crossing the line. Tolerance 1e-5 x (1 + scale) as above.
TEST(ClusterBoundGeometry, DistanceLineSegmentMatchesBruteForce) {
    Rng rng(14, 0);
    for (int i = 0; i < 1000; ++i) {
        const V3d origin = uniformInBox(rng, V3d(0.0), 5.0);
        const Vec3 direction = unitF(uniformDirection(rng));
        const V3d dd = toD(direction);
        const V3d a = uniformInBox(rng, V3d(0.0), 5.0);
        V3d b = a + uniformDirection(rng) * logUniform(rng, 1e-3, 5.0);
        const int kind = i % 5;
        if (kind == 1) b = a + dd * uniform(rng, -5.0, 5.0);  // parallel / antiparallel
        if (kind == 2) b = a;                                   // zero length
        if (kind == 3) {                                        // crosses the line (up to float rounding)
            const V3d onLine = origin + dd * uniform(rng, -5.0, 5.0);
            const V3d across = uniformDirection(rng);
            const double s = uniform(rng, 0.1, 2.0);
            b = onLine + across * s;
            const V3d start = onLine - across * uniform(rng, 0.1, 2.0);
            const double expected = bruteLineSegment(toF(origin), direction, toF(start), toF(b));
            const double got = distanceLineSegment(toF(origin), direction, toF(start), toF(b));
            EXPECT_NEAR(got, expected, 1e-5 * (1.0 + (start - origin).length())) << "crossing case " << i;
            EXPECT_LT(got, 1e-5) << "crossing case " << i;
            continue;
        }
        const double scale = 1.0 + (a - origin).length() + (b - a).length();
        const double expected = bruteLineSegment(toF(origin), direction, toF(a), toF(b));
        const double got = distanceLineSegment(toF(origin), direction, toF(a), toF(b));
        EXPECT_NEAR(got, expected, 1e-5 * scale) << "case " << i << " kind " << kind;
        if (kind == 1 || kind == 2) {  // every point of the segment is equally far from the line
            EXPECT_NEAR(got, distancePointLine(toD(toF(a)), toD(toF(origin)), dd.normalized()), 1e-5 * scale);
        }
    }
    // Exactly parallel, axis-aligned: the constant distance.
    EXPECT_DOUBLE_EQ(distanceLineSegment(Vec3(0.0f), Vec3(1, 0, 0), Vec3(-3, 0, 2), Vec3(7, 0, 2)), 2.0);
    EXPECT_DOUBLE_EQ(distanceLineSegment(Vec3(0.0f), Vec3(1, 0, 0), Vec3(7, 3, 4), Vec3(-3, 3, 4)), 5.0);
}

// ---- Random light trees around a camera line -------------------------------------------

struct Region {
    V3d centre{0.0};
    double halfSize = 2.0;
    bool clipToCube = false;  // keep everything inside the cube [-1, 1]^3 (mediumOnlyCube)
};

constexpr double kCubeHalf = 0.999;  // a little inside the cube's faces

// Clips a segment (origin, direction, length) to the cube; the origin must be inside.
double clipLengthToCube(const V3d& origin, const V3d& direction, double length) {
    for (int k = 0; k < 3; ++k) {
        if (direction[k] > 0) length = std::min(length, (kCubeHalf - origin[k]) / direction[k]);
        if (direction[k] < 0) length = std::min(length, (-kCubeHalf - origin[k]) / direction[k]);
    }
    return std::max(0.0, length);
}
V3d clampToCube(const V3d& p) {
    return {std::clamp(p.x, -kCubeHalf, kCubeHalf), std::clamp(p.y, -kCubeHalf, kCubeHalf),
            std::clamp(p.z, -kCubeHalf, kCubeHalf)};
}

struct ReferenceLine {
    V3d origin, w, e1, e2;  // unit w; e1, e2 complete an orthonormal frame
};

ReferenceLine randomReferenceLine(Rng& rng, const Region& region) {
    ReferenceLine line;
    line.origin = uniformInBox(rng, region.centre, 0.5 * region.halfSize);
    line.w = toD(unitF(uniformDirection(rng)));
    if (rng.next() < 0.15f) line.w = V3d(0.0), line.w[rng.nextUint() % 3] = 1.0;  // axis-parallel camera line
    line.e1 = orthogonal(line.w);
    line.e2 = line.w.cross(line.e1);
    return line;
}

enum class VrlKind { Generic, ZeroLength, Parallel, NearParallel, Coplanar, NearlyCrossing, Count };

Vrl randomVrl(Rng& rng, const Region& region, const ReferenceLine& line, int medium) {
    const auto kind = VrlKind(rng.nextUint() % uint32_t(VrlKind::Count));
    V3d origin, direction;
    double length = logUniform(rng, 1e-3, 2.0);
    const double phi = uniform(rng, 0.0, 2.0 * kPiD);
    const V3d radial = line.e1 * std::cos(phi) + line.e2 * std::sin(phi);
    switch (kind) {
        case VrlKind::Generic:
            origin = uniformInBox(rng, region.centre, region.halfSize);
            direction = uniformDirection(rng);
            break;
        case VrlKind::ZeroLength:
            origin = uniformInBox(rng, region.centre, region.halfSize);
            direction = uniformDirection(rng);
            length = 0.0;
            break;
        case VrlKind::Parallel:  // at distance 1e-4 .. 2 from the camera line, along +-w
            origin = line.origin + line.w * uniform(rng, -2.0, 2.0) + radial * logUniform(rng, 1e-4, 2.0);
            direction = line.w * (rng.next() < 0.5f ? 1.0 : -1.0);
            break;
        case VrlKind::NearParallel:
            origin = line.origin + line.w * uniform(rng, -2.0, 2.0) + radial * logUniform(rng, 1e-4, 2.0);
            direction = (line.w + uniformDirection(rng) * logUniform(rng, 1e-6, 1e-2)).normalized();
            break;
        case VrlKind::Coplanar: {  // in the plane (w, e1) through the line: may cross it
            const double alpha = uniform(rng, 0.0, 2.0 * kPiD);
            origin = line.origin + line.w * uniform(rng, -2.0, 2.0) + line.e1 * uniform(rng, -1.0, 1.0);
            direction = line.w * std::cos(alpha) + line.e1 * std::sin(alpha);
            break;
        }
        case VrlKind::NearlyCrossing: {  // closest approach 1e-6 .. 1e-2 somewhere along the VRL
            direction = uniformDirection(rng);
            const V3d foot = line.origin + line.w * uniform(rng, -2.0, 2.0);
            V3d across = direction.cross(line.w);
            across = across.length() > 1e-6 ? across.normalized() : radial;
            origin = foot + across * logUniform(rng, 1e-6, 1e-2) - direction * (length * rng.nextDouble());
            break;
        }
        case VrlKind::Count:
            break;
    }
    if (region.clipToCube) {
        origin = clampToCube(origin);
        length = clipLengthToCube(origin, direction, length);
    }
    Vrl v;
    v.origin = toF(origin);
    v.direction = unitF(direction);
    v.length = float(length);
    const double scale = logUniform(rng, 1e-2, 1e2);
    for (int c = 0; c < 3; ++c) v.flux[c] = rng.next() < 0.05f ? 0.0f : float(scale * uniform(rng, 1e-3, 1.0));
    v.medium = medium;
    return v;
}

// A light tree over `count` random VRLs (medium 0) around a random reference line
// of the default region, drawn from `rng` in that order.
LightTree randomTreeAroundALine(Rng& rng, int count) {
    const Region region;
    const ReferenceLine line = randomReferenceLine(rng, region);
    std::vector<Vrl> vrls;
    for (int i = 0; i < count; ++i) vrls.push_back(randomVrl(rng, region, line, 0));
    return LightTree::build(vrls);
}

enum class SegmentKind { AlongLine, Anywhere, NearVrl, Count };
constexpr const char* kSegmentKindNames[] = {"along the reference line", "anywhere", "grazing a VRL"};

// `along` > 0: segments on the reference line start that far before it (the VRLs then
// lie far down long segments).
CameraSegment randomSegment(Rng& rng, const Region& region, const ReferenceLine& line, const std::vector<Vrl>& vrls,
                            int medium, double along, SegmentKind& kind) {
    V3d origin, direction;
    const float pick = rng.next();
    double length = rng.next() < 0.1f ? 1e4 : logUniform(rng, 1e-3, 1e4);
    if (pick < 0.5f) {  // along the reference line (the VRLs were built around it)
        kind = SegmentKind::AlongLine;
        origin = line.origin + line.w * (uniform(rng, -3.0, 3.0) - along);
        direction = line.w * (along > 0.0 || rng.next() < 0.5f ? 1.0 : -1.0);
        length += along;
    } else if (pick < 0.75f) {  // anywhere
        kind = SegmentKind::Anywhere;
        origin = uniformInBox(rng, region.centre, region.halfSize);
        direction = uniformDirection(rng);
    } else {  // passing close to a point of some VRL
        kind = SegmentKind::NearVrl;
        const Vrl& v = vrls[rng.nextUint() % vrls.size()];
        direction = uniformDirection(rng);
        const V3d target = toD(v.origin) + toD(v.direction) * (double(v.length) * rng.nextDouble());
        origin = target + orthogonal(direction) * logUniform(rng, 1e-5, 0.1) - direction * uniform(rng, -1.0, 3.0);
    }
    if (region.clipToCube) {
        origin = clampToCube(origin);
        length = clipLengthToCube(origin, direction, length);
    }
    CameraSegment s;
    s.origin = toF(origin);
    s.direction = unitF(direction);
    s.length = float(length);
    s.medium = medium;
    for (int c = 0; c < 3; ++c) s.throughputBefore[c] = float(1.0 - rng.nextDouble());  // (0, 1]
    if (rng.next() < 0.2f) s.throughputBefore = Rgb(1.0f);
    return s;
}

// ---- 2./3. Estimate against bound --------------------------------------------------------

struct BoundCheck {
    uint64_t triples = 0;     // (node, segment, sample) evaluated against a finite bound
    uint64_t crossing = 0;    // lineCrossesNode: infinite bound, not estimated by the cut
    uint64_t violations = 0;  // triples with some channel above the bound
    uint64_t nonFinite = 0;   // NaN / inf estimates
    uint64_t positive = 0;    // triples with a nonzero estimate
    // Diagnostics: violations where h_min < 1e-7 x segment length (where VrlEstimator's
    // equiangular distance floor exceeds the true distance), and by segment kind.
    uint64_t floorRegimeViolations = 0;
    uint64_t triplesByKind[int(SegmentKind::Count)] = {};
    uint64_t violationsByKind[int(SegmentKind::Count)] = {};
    uint64_t scaledViolations = 0;  // against bound x SamplingPlan::alsoCountAgainst
    double maxRatio = 0.0;          // max over channels of estimate / bound
    std::string worst;              // the configuration of the largest ratio
};

struct SamplingPlan {
    uint64_t seed = 1;
    int trees = 1000;
    int segmentsPerTree = 16;
    int minVrls = 16, maxVrls = 64;
    double farFraction = 0.0;  // fraction of trees centred up to `farCentre` from the origin
    double farCentre = 50.0;
    double alongMax = 0.0;     // > 0: the VRLs lie 1 .. alongMax down the along-line segments
    Region region;
    ClusterBoundSettings settings;
    std::vector<int> vrlMedia{0};  // media the VRLs are drawn in
    int segmentMedium = 0;
    double alsoCountAgainst = 0.0;  // > 0: also count violations of bound x this factor
};

std::string describe(const Vrl& v, const LightTreeNode& node, const CameraSegment& s, double h, int channel,
                     double estimate, double bound) {
    char text[512];
    std::snprintf(text, sizeof text,
                  "node vrlCount=%u Lmax=%g rep(o=(%g,%g,%g) d=(%g,%g,%g) L=%g) segment(o=(%g,%g,%g) d=(%g,%g,%g) "
                  "S=%g) h_min=%g channel %d: estimate %g bound %g",
                  node.vrlCount, node.maxLength, v.origin.x, v.origin.y, v.origin.z, v.direction.x, v.direction.y,
                  v.direction.z, v.length, s.origin.x, s.origin.y, s.origin.z, s.direction.x, s.direction.y,
                  s.direction.z, s.length, h, channel, estimate, bound);
    return text;
}

BoundCheck checkBound(const Scene& scene, const SamplingPlan& plan) {
    BoundCheck result;
    const VrlEstimator estimator(scene, 1);
    for (int t = 0; t < plan.trees; ++t) {
        Rng rng(plan.seed, uint64_t(t));
        Region region = plan.region;
        if (rng.nextDouble() < plan.farFraction) region.centre = uniformInBox(rng, V3d(0.0), plan.farCentre);
        const ReferenceLine line = randomReferenceLine(rng, region);
        const double along = plan.alongMax > 0.0 ? logUniform(rng, 1.0, plan.alongMax) : 0.0;
        const int count = plan.minVrls + int(rng.nextUint() % uint32_t(plan.maxVrls - plan.minVrls + 1));
        std::vector<Vrl> vrls;
        for (int i = 0; i < count; ++i)
            vrls.push_back(randomVrl(rng, region, line, plan.vrlMedia[rng.nextUint() % plan.vrlMedia.size()]));
        LightTreeSettings treeSettings;
        treeSettings.seed = uint64_t(t);
        treeSettings.partitionSize = rng.next() < 0.5f ? 2048u : 8u;  // global and hybrid builds
        const LightTree tree = LightTree::build(vrls, treeSettings);
        const ClusterBound bound(scene, tree, plan.settings);
        for (int k = 0; k < plan.segmentsPerTree; ++k) {
            SegmentKind kind;
            const CameraSegment segment = randomSegment(rng, region, line, tree.vrls(), plan.segmentMedium, along, kind);
            for (size_t n = 0; n < tree.nodes().size(); ++n) {
                const LightTreeNode& node = tree.nodes()[n];
                bool crosses = false;
                const Rgb b = bound.bound(int32_t(n), segment, &crosses);
                if (crosses) {
                    ++result.crossing;
                    EXPECT_TRUE(std::isinf(b.x) && std::isinf(b.y) && std::isinf(b.z));
                    continue;
                }
                // As the cut: the representative carrying the cluster flux, its own stream.
                Vrl representative = tree.vrls()[node.representative];
                representative.flux = node.clusterFlux;
                Rng sampleRng(plan.seed ^ 0x5bd1e995u, Rng::combine(uint64_t(t), uint64_t(k) * 4096 + n));
                const Rgb e = estimator.contribution(representative, segment, sampleRng);
                ++result.triples;
                ++result.triplesByKind[int(kind)];
                if (!isFinite(e)) {
                    ++result.nonFinite;
                    continue;
                }
                if (!isBlack(e)) ++result.positive;
                bool violated = false, scaledViolated = false;
                for (int c = 0; c < 3; ++c) {
                    if (!(e[c] <= b[c])) violated = true;
                    if (plan.alsoCountAgainst > 0.0 && !(e[c] <= b[c] * plan.alsoCountAgainst)) scaledViolated = true;
                    if (!(e[c] > 0.0f)) continue;
                    const double ratio = b[c] > 0.0f ? double(e[c]) / double(b[c]) : kInfinity;
                    if (ratio > result.maxRatio) {
                        result.maxRatio = ratio;
                        result.worst = describe(representative, node, segment,
                                                bound.minimumDistance(int32_t(n), segment), c, e[c], b[c]);
                    }
                }
                result.scaledViolations += scaledViolated;
                if (violated) {
                    ++result.violations;
                    ++result.violationsByKind[int(kind)];
                    if (bound.minimumDistance(int32_t(n), segment) < 1e-7 * segment.length) ++result.floorRegimeViolations;
                }
            }
        }
    }
    return result;
}

double rate(uint64_t count, uint64_t total) { return double(count) / double(std::max<uint64_t>(1, total)); }

void print(const char* name, const BoundCheck& r) {
    std::printf("[ %s ] %llu triples (+%llu crossing: infinite bound), %llu nonzero; violations %llu (%.4g%%, "
                "%llu with h_min < 1e-7 S); max estimate/bound %.6f\n",
                name, (unsigned long long)r.triples, (unsigned long long)r.crossing, (unsigned long long)r.positive,
                (unsigned long long)r.violations, 100.0 * rate(r.violations, r.triples),
                (unsigned long long)r.floorRegimeViolations, r.maxRatio);
    for (int k = 0; k < int(SegmentKind::Count); ++k)
        std::printf("    segments %s: %llu triples, %llu violations (%.4g%%)\n", kSegmentKindNames[k],
                    (unsigned long long)r.triplesByKind[k], (unsigned long long)r.violationsByKind[k],
                    100.0 * rate(r.violationsByKind[k], r.triplesByKind[k]));
    std::printf("    largest ratio: %s\n", r.worst.c_str());
}

std::unique_ptr<Scene> unboundedScene(const Rgb& sigmaS, const Rgb& sigmaA, float g) {
    return Scene::build(test::pointLightInInfiniteMedium(Rgb(1.0f), Vec3(0.0f), sigmaS, sigmaA, g));
}

void expectNoViolation(const BoundCheck& r) {
    EXPECT_EQ(r.nonFinite, 0u);
    EXPECT_EQ(r.violations, 0u) << r.floorRegimeViolations
                                << " of them with h_min < 1e-7 x segment length; largest ratio: " << r.worst;
}

// What Scene decides for the media these tests use: an unbounded medium (no bounding
// shapes) and the null-bounded cube are both "convex" (T_r(h_min) applies), and
// neither needs visibility rays (the estimator uses T_r(w) directly).
TEST(ClusterBound, SceneClassifiesUnboundedAndCubeMediaAsConvex) {
    const auto unbounded = unboundedScene(Rgb(0.5f), Rgb(0.1f), 0.0f);
    ASSERT_EQ(unbounded->media().size(), 1u);
    EXPECT_TRUE(unbounded->media()[0].boundaryConvex());
    EXPECT_FALSE(unbounded->mediumNeedsVisibility(0));
    const auto cube = Scene::build(test::mediumOnlyCube(Rgb(0.5f), Rgb(0.1f), 0.0f));
    ASSERT_EQ(cube->media().size(), 1u);
    EXPECT_TRUE(cube->media()[0].boundaryConvex());
    EXPECT_FALSE(cube->mediumNeedsVisibility(0));
}

// 2000 trees x 16-64 VRLs (~80 nodes) x 16 segments: ~2.4e6 triples per medium (seeds
// 101, 102), VRLs within a few units of the origin, segments up to 1e4 long. Chromatic
// sigma_s so channels differ; exact distances below 32 VRLs (the default).
TEST(ClusterBound, BoundsIsotropicEstimateInUnboundedMedium) {
    const auto scene = unboundedScene(Rgb(0.2f, 0.5f, 1.0f), Rgb(0.0f), 0.0f);
    SamplingPlan plan;
    plan.seed = 101;
    plan.trees = 2000;
    const BoundCheck r = checkBound(*scene, plan);
    print("isotropic, unbounded, no absorption", r);
    EXPECT_GE(r.triples, 2'000'000u);
    EXPECT_GT(r.positive, r.triples / 2);
    EXPECT_GT(r.crossing, 0u);
    expectNoViolation(r);
    EXPECT_GT(r.maxRatio, 0.9);  // the sampling reaches near-tight configurations
}

TEST(ClusterBound, BoundsIsotropicEstimateInAbsorbingUnboundedMedium) {
    const auto scene = unboundedScene(Rgb(0.2f, 0.5f, 1.0f), Rgb(0.6f, 0.05f, 0.3f), 0.0f);
    SamplingPlan plan;
    plan.seed = 102;
    plan.trees = 2000;
    const BoundCheck r = checkBound(*scene, plan);
    print("isotropic, unbounded, absorbing", r);
    EXPECT_GE(r.triples, 2'000'000u);
    expectNoViolation(r);
    EXPECT_GT(r.maxRatio, 0.9);
}

// Box distances everywhere (exactDistanceBelow = 0): looser, still a bound (seed 103,
// 500 trees, ~4e5 triples; a third of the nodes are crossed by their box distance).
TEST(ClusterBound, BoundsIsotropicEstimateWithBoxDistancesOnly) {
    const auto scene = unboundedScene(Rgb(0.7f, 0.4f, 0.1f), Rgb(0.2f), 0.0f);
    SamplingPlan plan;
    plan.seed = 103;
    plan.trees = 500;
    plan.settings.exactDistanceBelow = 0;
    const BoundCheck r = checkBound(*scene, plan);
    print("isotropic, unbounded, box distances only", r);
    EXPECT_GE(r.triples, 300'000u);
    expectNoViolation(r);
}

// Sphere distances for large nodes (sphereDistanceBeyond = 2: the bounding sphere's
// distance when it is beyond two radii, a lower bound of the box's): still a bound
// (seed 123, 300 trees with up to 200 VRLs, so that nodes above the exact-distance
// size exist, ~1e6 triples).
TEST(ClusterBound, BoundsIsotropicEstimateWithSphereDistances) {
    const auto scene = unboundedScene(Rgb(0.7f, 0.4f, 0.1f), Rgb(0.2f), 0.0f);
    SamplingPlan plan;
    plan.seed = 123;
    plan.trees = 300;
    plan.minVrls = 100, plan.maxVrls = 200;
    plan.settings.sphereDistanceBeyond = 2.0f;
    const BoundCheck r = checkBound(*scene, plan);
    print("isotropic, unbounded, sphere distances beyond 2 radii", r);
    EXPECT_GE(r.triples, 300'000u);
    expectNoViolation(r);
    // The sphere path is taken: far from a 150-VRL tree, large nodes get a distance
    // below the box's (never above it), small ones the same.
    Rng rng(124, 0);
    const LightTree tree = randomTreeAroundALine(rng, 150);
    const ClusterBound box(*scene, tree), sphere(*scene, tree, plan.settings);
    CameraSegment far;
    far.origin = Vec3(-30.0f, 20.0f, 25.0f);
    far.direction = Vec3(1.0f, 0.0f, 0.0f);
    far.length = 60.0f;
    far.medium = 0;
    int below = 0;
    for (size_t n = 0; n < tree.nodes().size(); ++n) {
        const double b = box.minimumDistance(int32_t(n), far), s = sphere.minimumDistance(int32_t(n), far);
        EXPECT_LE(s, b * (1.0 + 1e-9)) << "node " << n;
        if (tree.nodes()[n].vrlCount <= plan.settings.exactDistanceBelow) {
            EXPECT_EQ(s, b);
        }
        below += s < b;
    }
    EXPECT_GT(below, 0) << "no node took the sphere distance";
}

// Convex null-bounded cube [-1,1]^3 (mediumOnlyCube), VRLs and camera segments clipped
// to its inside (seed 104, 800 trees, ~1e6 triples).
TEST(ClusterBound, BoundsIsotropicEstimateInConvexCube) {
    const auto scene = Scene::build(test::mediumOnlyCube(Rgb(1.5f, 0.8f, 0.3f), Rgb(0.4f, 0.9f, 0.1f), 0.0f));
    SamplingPlan plan;
    plan.seed = 104;
    plan.trees = 800;
    plan.region.halfSize = 0.9;
    plan.region.clipToCube = true;
    const BoundCheck r = checkBound(*scene, plan);
    print("isotropic, convex cube", r);
    EXPECT_GE(r.triples, 800'000u);
    expectNoViolation(r);
    EXPECT_GT(r.maxRatio, 0.5);
}

// Nodes spanning two media (node.medium = -1: max sigma_s, no T_r(h_min)) and VRLs in
// another medium than the segment (seed 105, 300 trees, ~3.6e5 triples). Two
// overlapping unbounded isotropic media, no shapes: the estimator's transmittance
// between u and v is that of the segment's medium.
TEST(ClusterBound, BoundsIsotropicEstimateAcrossMedia) {
    SceneDescription description = test::pointLightInInfiniteMedium(Rgb(1.0f), Vec3(0.0f), Rgb(0.3f, 0.6f, 0.9f),
                                                                    Rgb(0.2f), 0.0f);
    MediumDescription second;
    second.id = "second";
    second.sigmaS = Rgb(1.2f, 0.1f, 0.5f);
    second.sigmaA = Rgb(0.05f);
    description.media.push_back(second);
    const auto scene = Scene::build(description);
    SamplingPlan plan;
    plan.seed = 105;
    plan.trees = 300;
    plan.vrlMedia = {0, 1};
    const BoundCheck r = checkBound(*scene, plan);
    print("isotropic, two media", r);
    EXPECT_GE(r.triples, 300'000u);
    expectNoViolation(r);
}

// Float coordinates far from the origin: trees centred up to 50 units away, or lying
// 1 .. 1000 units down long camera segments (seed 108, 2 x 400 trees, ~1e6 triples).
// Distances down to 1e-4 are then only a few hundred float steps of the coordinates:
// the bound must absorb the arithmetic's absolute rounding, not only 0.1%.
// Both far regimes, `trees` trees each, seeds `seed` and seed + 1: no violation.
void expectNoViolationFarFromTheOrigin(const Scene& scene, uint64_t seed, int trees, const std::string& name) {
    SamplingPlan plan;
    plan.seed = seed;
    plan.trees = trees;
    plan.farFraction = 1.0;
    BoundCheck r = checkBound(scene, plan);
    print((name + ", centred up to 50 from the origin").c_str(), r);
    expectNoViolation(r);
    plan.seed = seed + 1;
    plan.farFraction = 0.0;
    plan.alongMax = 1000.0;
    r = checkBound(scene, plan);
    print((name + ", VRLs up to 1000 down the segment").c_str(), r);
    expectNoViolation(r);
}

TEST(ClusterBound, BoundsIsotropicEstimateFarFromTheOrigin) {
    const auto scene = unboundedScene(Rgb(0.2f, 0.5f, 1.0f), Rgb(0.0f), 0.0f);
    expectNoViolationFarFromTheOrigin(*scene, 108, 400, "isotropic, unbounded");
}

// The tight case of the derivation, deterministically: a VRL parallel to the camera
// segment at distance h (uniform v, so every sample is theta(v) L / h against the
// bound's theta_max L / h), with foot points inside the segment, in a nearly clear
// medium (sigma_s = 1e-5: transmittance > 0.999 near the foot). Each of 2000 samples
// per (h, S) must stay below the bound, and their mean ratio above 0.8 (theta(v) is
// close to theta_max). S = 1e30 is what cameraSegments gives a ray that leaves an
// unbounded medium.
TEST(ClusterBound, ParallelVrlEstimateIsNearlyTight) {
    const auto scene = unboundedScene(Rgb(1e-5f), Rgb(0.0f), 0.0f);
    const VrlEstimator estimator(*scene, 1);
    for (double h : {1e-4, 1e-2, 1.0}) {
        for (double s : {1.0, 100.0, 1e4, 1e6, 1e30}) {
            CameraSegment segment;
            segment.origin = Vec3(0.3f, -0.2f, 0.1f);
            segment.direction = unitF(V3d(1.0, 2.0, 2.0));
            segment.length = float(s);
            segment.medium = 0;
            const double foot = std::min(0.5 * s, 100.0 * h + 0.1);  // centre of the VRL's foot points
            const double vrlLength = std::min(0.2, 0.5 * s);
            const V3d w = toD(segment.direction);
            Vrl vrl;
            vrl.origin = toF(toD(segment.origin) + w * (foot - 0.5 * vrlLength) + orthogonal(w) * h);
            vrl.direction = segment.direction;
            vrl.length = float(vrlLength);
            vrl.flux = Rgb(1.0f);
            vrl.medium = 0;
            const LightTree tree = LightTree::build({vrl});
            const ClusterBound bound(*scene, tree);
            const Rgb b = bound.bound(0, segment);
            double maxRatio = 0.0, sum = 0.0;
            constexpr int kSamples = 2000;
            for (int i = 0; i < kSamples; ++i) {
                Rng rng(110, uint64_t(i));
                const double ratio = double(estimator.contribution(vrl, segment, rng).x) / double(b.x);
                maxRatio = std::max(maxRatio, ratio);
                sum += ratio;
            }
            EXPECT_LE(maxRatio, 1.0) << "h=" << h << " S=" << s;
            EXPECT_GE(sum / kSamples, 0.8) << "h=" << h << " S=" << s;
            std::printf("[ parallel VRL ] h=%-6g S=%-6g mean estimate/bound %.4f, max %.4f\n", h, s, sum / kSamples,
                        maxRatio);
        }
    }
}

// A camera line through a VRL exactly (distance 0 in exact arithmetic and in the
// function's) gives lineCrossesNode = true and an infinite bound, for the leaf and
// every ancestor; a line crossing a large node's box (> exactDistanceBelow VRLs)
// without touching its VRLs also does; with exact distances a small node does not.
TEST(ClusterBound, ExactlyCrossingLineGivesInfiniteBound) {
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.1f), 0.0f);
    std::vector<Vrl> vrls;
    // Leaf 0 crosses the x axis at (0.5, 0, 0); the others lie on a grid off the axis.
    vrls.push_back({Vec3(0.5f, -1.0f, 0.0f), Vec3(0, 1, 0), 2.0f, Rgb(1.0f), 0});
    for (int i = 0; i < 40; ++i) {
        const float y = 0.5f + 0.1f * float(i % 8), z = (i / 8 % 2 ? 1.0f : -1.0f) * (0.3f + 0.1f * float(i / 16));
        vrls.push_back({Vec3(-2.0f + 0.1f * float(i), y, z), Vec3(0, 0, 1), 0.2f, Rgb(0.5f, 1.0f, 2.0f), 0});
    }
    const LightTree tree = LightTree::build(vrls);
    const ClusterBound bound(*scene, tree);
    CameraSegment segment;
    segment.origin = Vec3(-5.0f, 0.0f, 0.0f);
    segment.direction = Vec3(1, 0, 0);
    segment.length = 3.0f;  // ends at x = -2: the *line* matters, not the segment
    segment.medium = 0;
    bool crosses = false;
    const Rgb leafBound = bound.bound(0, segment, &crosses);
    EXPECT_TRUE(crosses);
    EXPECT_TRUE(std::isinf(leafBound.x) && std::isinf(leafBound.y) && std::isinf(leafBound.z));
    EXPECT_EQ(bound.minimumDistance(0, segment), 0.0);
    // Every ancestor of leaf 0 contains it: crossing too.
    std::vector<int32_t> parent(tree.nodes().size(), -1);
    for (size_t n = 0; n < tree.nodes().size(); ++n)
        if (!tree.nodes()[n].isLeaf()) parent[tree.nodes()[n].left] = parent[tree.nodes()[n].right] = int32_t(n);
    int ancestors = 0;
    for (int32_t n = parent[0]; n >= 0; n = parent[n], ++ancestors) {
        crosses = false;
        EXPECT_TRUE(std::isinf(bound.bound(n, segment, &crosses).x));
        EXPECT_TRUE(crosses) << "ancestor " << n;
    }
    EXPECT_GT(ancestors, 0);
    // A line through the root's box missing every VRL: the root (41 VRLs) uses its box.
    CameraSegment miss = segment;
    miss.origin = Vec3(-5.0f, 0.9f, 0.05f);  // inside the root box's y/z extent, between the VRLs
    const LightTreeNode& root = tree.nodes()[tree.root()];
    ASSERT_GT(root.vrlCount, 32u);
    ASSERT_EQ(distanceLineBox(miss.origin, miss.direction, root.box), 0.0);
    crosses = false;
    EXPECT_TRUE(std::isinf(bound.bound(tree.root(), miss, &crosses).x));
    EXPECT_TRUE(crosses);
    // The same line against a node of <= 32 VRLs whose box it crosses: exact distance, finite bound.
    int checked = 0;
    for (size_t n = 0; n < tree.nodes().size(); ++n) {
        const LightTreeNode& node = tree.nodes()[n];
        if (node.isLeaf() || node.vrlCount > 32 || distanceLineBox(miss.origin, miss.direction, node.box) > 0.0)
            continue;
        crosses = true;
        const Rgb b = bound.bound(int32_t(n), miss, &crosses);
        EXPECT_FALSE(crosses);
        EXPECT_TRUE(isFinite(b));
        EXPECT_GT(bound.minimumDistance(int32_t(n), miss), 0.0);
        ++checked;
    }
    EXPECT_GT(checked, 0);
    // A finite bound always reports no crossing.
    crosses = true;
    CameraSegment away = segment;
    away.origin = Vec3(-5.0f, 10.0f, 10.0f);
    EXPECT_TRUE(isFinite(bound.bound(tree.root(), away, &crosses)));
    EXPECT_FALSE(crosses);
}

// HG g = 0.7 (one medium for both ends), epsilon = 1: the bound is a heuristic. Seed
// 106, 800 trees (~1e6 triples). The paper reports < 0.02% violations in its scenes;
// these configurations are adversarial (VRLs parallel to or grazing the camera line,
// where the forward-peaked product f(u) f(v) reaches ((1+g)/(1-g)^2)^2 ~ 360 times the
// isotropic one and the estimator's 8-bin fit of it cannot follow), so the rate is
// printed (also per segment kind, and against the bound without the (1 + epsilon)
// factor) and only capped loosely at 5%: a bound that dropped a geometric factor or used
// the paper's misprinted theta_max fails it by far. That the factor is applied at all is
// checked exactly by the next test.
TEST(ClusterBound, HenyeyGreensteinViolationRateIsSmall) {
    const auto scene = unboundedScene(Rgb(0.2f, 0.5f, 1.0f), Rgb(0.1f), 0.7f);
    SamplingPlan plan;
    plan.seed = 106;
    plan.trees = 800;
    plan.settings.hgBound = HgBound::Epsilon;
    plan.settings.anisotropyEpsilon = 1.0f;
    plan.alsoCountAgainst = 1.0 / (1.0 + plan.settings.anisotropyEpsilon);
    const BoundCheck r = checkBound(*scene, plan);
    print("HG g=0.7, epsilon=1", r);
    const double violationRate = rate(r.violations, r.triples);
    std::printf("[ HG g=0.7 ] violation rate %.4f%% (%llu of %llu); %.4f%% against the bound without (1 + epsilon)\n",
                100.0 * violationRate, (unsigned long long)r.violations, (unsigned long long)r.triples,
                100.0 * rate(r.scaledViolations, r.triples));
    EXPECT_GE(r.triples, 800'000u);
    EXPECT_EQ(r.nonFinite, 0u);
    EXPECT_TRUE(std::isfinite(violationRate));
    EXPECT_LT(violationRate, 0.05);
    EXPECT_LE(r.violations, r.scaledViolations);
}

// The proven HG bound (HgBound::Cones, the default), for forward and backward
// scattering up to g = 0.99: zero violations over ~1e6 (node, segment, sample)
// triples per g (seed 110 + index, 800 trees x 16 segments, the adversarial VRL
// and segment kinds of the isotropic tests, chromatic sigma_s and sigma_a). An
// inequality, not a statistic: a single estimate above its bound fails. The
// largest ratio is printed (how tight the bound gets).
class HgConeBound : public ::testing::TestWithParam<float> {};

TEST_P(HgConeBound, BoundsEveryEstimate) {
    const float g = GetParam();
    const auto scene = unboundedScene(Rgb(0.2f, 0.5f, 1.0f), Rgb(0.3f, 0.05f, 0.1f), g);
    SamplingPlan plan;
    plan.seed = 110 + uint64_t(std::lround(100.0f * (g + 1.0f)));
    plan.trees = 800;
    ASSERT_EQ(plan.settings.hgBound, HgBound::Cones) << "the proven bound is the default";
    const BoundCheck r = checkBound(*scene, plan);
    const std::string name = "HG cones, g=" + std::to_string(g);
    print(name.c_str(), r);
    EXPECT_GE(r.triples, 800'000u);
    EXPECT_GT(r.positive, r.triples / 2);
    expectNoViolation(r);
    EXPECT_GT(r.maxRatio, 1e-3) << "the bound should not be vacuous";
}

INSTANTIATE_TEST_SUITE_P(ClusterBound, HgConeBound, ::testing::Values(-0.9f, -0.5f, 0.3f, 0.7f, 0.9f, 0.99f),
                         [](const ::testing::TestParamInfo<float>& info) {
                             std::string name = "g" + std::to_string(int(std::lround(100.0f * info.param)));
                             std::replace(name.begin(), name.end(), '-', 'm');
                             return name;
                         });

// Nodes spanning two media of opposite g (node.medium = -1: the phase extremes over
// both), VRLs in another medium than the segment, an isotropic third medium, and
// trees far from the origin or far down long segments (seed 120..122, 3 x 300 trees).
TEST(ClusterBound, HgConeBoundAcrossMediaAndFarAway) {
    SceneDescription description = test::pointLightInInfiniteMedium(Rgb(1.0f), Vec3(0.0f), Rgb(0.3f, 0.6f, 0.9f),
                                                                    Rgb(0.2f), 0.8f);
    for (const auto& [id, g] : {std::pair<const char*, float>{"backward", -0.6f}, {"isotropic", 0.0f}}) {
        MediumDescription m;
        m.id = id;
        m.sigmaS = Rgb(1.2f, 0.1f, 0.5f);
        m.sigmaA = Rgb(0.05f);
        if (g != 0.0f) m.phase = {PhaseDescription::Kind::HenyeyGreenstein, g};
        description.media.push_back(m);
    }
    const auto scene = Scene::build(description);
    ASSERT_EQ(scene->media().size(), 3u);
    SamplingPlan plan;
    plan.seed = 120;
    plan.trees = 300;
    plan.vrlMedia = {0, 1, 2};
    for (int segmentMedium : {0, 2}) {
        plan.segmentMedium = segmentMedium;
        const BoundCheck r = checkBound(*scene, plan);
        print(segmentMedium == 0 ? "HG cones, three media, camera in g=0.8"
                                 : "HG cones, three media, camera in the isotropic one",
              r);
        EXPECT_GE(r.triples, 300'000u);
        expectNoViolation(r);
    }
    const auto hg = unboundedScene(Rgb(0.2f, 0.5f, 1.0f), Rgb(0.0f), 0.9f);
    expectNoViolationFarFromTheOrigin(*hg, 121, 300, "HG cones g=0.9");
}

// The cone bound is the isotropic bound with its phase factor 1/(4 pi)^2 replaced by
// F / (w + (1 - w) F_min / F): on the same tree and segment its ratio to the
// isotropic bound lies in [min HG^2 (4 pi)^2, max HG^2 (4 pi)^2 / w]. Far from the
// node (narrow cones) it is close to the exact phase product of the geometry: 1/100
// of the isotropic bound where light scatters backwards twice, 350x where it
// scatters forwards twice.
TEST(ClusterBound, HgConeBoundScalesTheIsotropicStructure) {
    const float g = 0.7f;
    const auto isotropic = unboundedScene(Rgb(0.02f, 0.05f, 0.1f), Rgb(0.01f), 0.0f);
    const auto hg = unboundedScene(Rgb(0.02f, 0.05f, 0.1f), Rgb(0.01f), g);
    std::vector<Vrl> vrls;  // 16 VRLs near the origin, all along +x
    for (int i = 0; i < 16; ++i)
        vrls.push_back({Vec3(0.1f * float(i % 4), 0.1f * float(i / 4), 0.0f), Vec3(1, 0, 0), 0.2f, Rgb(1.0f), 0});
    const LightTree tree = LightTree::build(vrls);
    const ClusterBound isotropicBound(*isotropic, tree), hgBound(*hg, tree);
    const double hgMax = (1.0 + g) / ((1.0 - g) * (1.0 - g)), hgMin = (1.0 - g) / ((1.0 + g) * (1.0 + g));
    const auto ratioAt = [&](const Vec3& origin, const Vec3& direction) {
        CameraSegment s;
        s.origin = origin;
        s.direction = direction;
        s.length = 0.5f;
        s.medium = 0;
        const Rgb bi = isotropicBound.bound(tree.root(), s), bh = hgBound.bound(tree.root(), s);
        EXPECT_TRUE(isFinite(bi));
        for (size_t n = 0; n < tree.nodes().size(); ++n) {
            const Rgb ni = isotropicBound.bound(int32_t(n), s), nh = hgBound.bound(int32_t(n), s);
            for (int c = 0; c < 3; ++c) {
                if (!(ni[c] > 0.0f)) continue;
                const double q = double(nh[c]) / double(ni[c]);
                EXPECT_GE(q, hgMin * hgMin * 0.999) << "node " << n;
                EXPECT_LE(q, hgMax * hgMax / VrlEstimator::kHgUniformWeight * 1.001) << "node " << n;
            }
        }
        return double(bh.y) / double(bi.y);
    };
    // toU is about -x from the VRLs to a segment at x = -50, +x to one at x = +50
    // (0.5 off their plane, so that the camera line misses them). The
    // phase at v compares toU with the VRLs' +x, the one at u compares it with the
    // direction to the camera, -(segment direction).
    const double backTwice = ratioAt(Vec3(-50.0f, 0.2f, 0.5f), Vec3(-1, 0, 0));  // cos -1 at v and at u
    const double backThenForward = ratioAt(Vec3(-50.0f, 0.2f, 0.5f), Vec3(1, 0, 0));  // -1 at v, +1 at u
    const double forwardTwice = ratioAt(Vec3(50.0f, 0.2f, 0.5f), Vec3(-1, 0, 0));     // +1 at v and at u
    std::printf("[ HG cones g=0.7 ] bound / isotropic bound: backward twice %.4f (HG(-1)^2 (4 pi)^2 = %.4f), "
                "backward then forward %.3f (%.3f), forward twice %.1f (%.1f)\n",
                backTwice, hgMin * hgMin, backThenForward, hgMin * hgMax, forwardTwice, hgMax * hgMax);
    // The cones from 50 units are ~0.01 rad wide, where HG is flat: within 5% of the exact products.
    EXPECT_NEAR(backTwice, hgMin * hgMin, 0.05 * hgMin * hgMin);
    EXPECT_NEAR(backThenForward, hgMin * hgMax, 0.05 * hgMin * hgMax);
    EXPECT_NEAR(forwardTwice, hgMax * hgMax, 0.05 * hgMax * hgMax);
}

// Anisotropic media scale the isotropic bound by exactly (1 + epsilon); isotropic media
// ignore epsilon. Same tree and segment in an isotropic and an HG medium of equal
// coefficients (relative tolerance 1e-6: float products).
TEST(ClusterBound, AnisotropyEpsilonScalesTheIsotropicBound) {
    const auto isotropic = unboundedScene(Rgb(0.2f, 0.5f, 1.0f), Rgb(0.1f), 0.0f);
    const auto hg = unboundedScene(Rgb(0.2f, 0.5f, 1.0f), Rgb(0.1f), 0.7f);
    Rng rng(111, 0);
    const LightTree tree = randomTreeAroundALine(rng, 40);
    CameraSegment segment;  // its line z = 10 passes clear of the VRLs (|z| < 4): finite bounds
    segment.origin = Vec3(-5.0f, 0.3f, 10.0f);
    segment.direction = Vec3(1.0f, 0.0f, 0.0f);
    segment.length = 20.0f;
    segment.medium = 0;
    segment.throughputBefore = Rgb(0.9f, 0.5f, 0.7f);
    for (float epsilon : {0.0f, 1.0f, 3.0f}) {
        ClusterBoundSettings settings;
        settings.hgBound = HgBound::Epsilon;
        settings.anisotropyEpsilon = epsilon;
        const ClusterBound isotropicBound(*isotropic, tree, settings), hgBound(*hg, tree, settings);
        ClusterBoundSettings zero = settings;
        zero.anisotropyEpsilon = 0.0f;
        const ClusterBound isotropicZero(*isotropic, tree, zero);
        for (size_t n = 0; n < tree.nodes().size(); ++n) {
            const Rgb bi = isotropicBound.bound(int32_t(n), segment), bh = hgBound.bound(int32_t(n), segment);
            const Rgb b0 = isotropicZero.bound(int32_t(n), segment);
            ASSERT_TRUE(isFinite(bi));
            for (int c = 0; c < 3; ++c) {
                EXPECT_EQ(bi[c], b0[c]) << "isotropic bounds do not depend on epsilon";
                EXPECT_NEAR(bh[c], bi[c] * (1.0 + epsilon), 1e-6 * bh[c]) << "epsilon " << epsilon << " node " << n;
            }
        }
    }
}

// ---- 4. Exact distances ------------------------------------------------------------------

// Seed 107, 300 trees x 8 segments: minimumDistance of every node with <= 32 VRLs is
// the minimum of distanceLineSegment over its VRLs (same arithmetic: exact equality),
// never below the box distance (tolerance 1e-6 x scale: both are computed in double
// from float data); larger nodes use the box distance exactly.
TEST(ClusterBound, ExactDistanceForSmallNodes) {
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.1f), 0.0f);
    int small = 0, large = 0;
    for (int t = 0; t < 300; ++t) {
        Rng rng(107, uint64_t(t));
        const Region region;
        const ReferenceLine line = randomReferenceLine(rng, region);
        const int count = 16 + int(rng.nextUint() % 49);
        std::vector<Vrl> vrls;
        for (int i = 0; i < count; ++i) vrls.push_back(randomVrl(rng, region, line, 0));
        const LightTree tree = LightTree::build(vrls);
        ClusterBoundSettings settings;
        settings.exactDistanceBelow = 32;
        const ClusterBound bound(*scene, tree, settings);
        // VRLs below each node.
        std::vector<std::vector<uint32_t>> below(tree.nodes().size());
        for (size_t n = 0; n < tree.nodes().size(); ++n) {  // leaves first, then parents after children
            const LightTreeNode& node = tree.nodes()[n];
            if (node.isLeaf()) {
                below[n] = {node.representative};
            } else {
                below[n] = below[node.left];
                below[n].insert(below[n].end(), below[node.right].begin(), below[node.right].end());
            }
        }
        for (int k = 0; k < 8; ++k) {
            SegmentKind kind;
            const CameraSegment segment = randomSegment(rng, region, line, tree.vrls(), 0, 0.0, kind);
            for (size_t n = 0; n < tree.nodes().size(); ++n) {
                const LightTreeNode& node = tree.nodes()[n];
                ASSERT_EQ(below[n].size(), node.vrlCount);
                const double got = bound.minimumDistance(int32_t(n), segment);
                const double box = distanceLineBox(segment.origin, segment.direction, node.box);
                if (node.vrlCount <= 32) {
                    double exact = std::numeric_limits<double>::infinity();
                    for (uint32_t i : below[n]) {
                        const Vrl& v = tree.vrls()[i];
                        exact = std::min(exact, distanceLineSegment(segment.origin, segment.direction, v.origin, v.end()));
                    }
                    EXPECT_EQ(got, exact) << "tree " << t << " node " << n;
                    const double scale = 1.0 + (toD(segment.origin) - toD(node.box.center())).length();
                    EXPECT_GE(got, box - 1e-6 * scale) << "tree " << t << " node " << n;
                    ++small;
                } else {
                    EXPECT_EQ(got, box) << "tree " << t << " node " << n;
                    ++large;
                }
            }
        }
    }
    std::printf("[ exact distances ] %d small-node and %d large-node checks\n", small, large);
    EXPECT_GT(large, 100);
}

}  // namespace
}  // namespace vrl
