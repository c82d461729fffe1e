#include "render/lightcuts/cuts/vrl_importance.h"

#include "render/core/distance.h"
#include "render/media/homogeneous_medium.h"
#include "render/scene/scene.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace vrl {

namespace {

// atan2(y, x) for y > 0, in (0, pi): a degree-11 odd minimax polynomial of atan on
// [0, 1] (absolute error < 1e-5 rad) after the usual octant reduction. Positive
// for every y > 0: atan(z) ~ 0.99998 z near 0, and pi/2 - atan(z) >= pi/4 - 1e-5.
double positiveAtan2(double y, double x) {
    const auto atanUnit = [](double z) {  // z in [0, 1]
        const double s = z * z;
        return z * (0.99997726 +
                    s * (-0.33262347 + s * (0.19354346 + s * (-0.11643287 + s * (0.05265332 + s * -0.01172120)))));
    };
    const double ax = std::abs(x);
    if (ax >= y) {
        const double a = atanUnit(y / ax);
        return x >= 0.0 ? a : M_PI - a;
    }
    const double a = atanUnit(ax / y);
    return x >= 0.0 ? 0.5 * M_PI - a : 0.5 * M_PI + a;
}

// An upper bound of the distance between the line (o, unit d) and the box [lo, hi]:
// three alternating projections (line -> box -> line) from the line's point
// nearest the box's centre, then the distance between the last pair of points.
float approximateDistanceLineBox(const Vec3& o, const Vec3& d, const Vec3& lo, const Vec3& hi) {
    const auto clampToBox = [&](const Vec3& p) {
        return Vec3(std::clamp(p.x, lo.x, hi.x), std::clamp(p.y, lo.y, hi.y), std::clamp(p.z, lo.z, hi.z));
    };
    float t = d.dot((lo + hi) * 0.5f - o);
    for (int i = 0; i < 3; ++i) t = d.dot(clampToBox(o + d * t) - o);
    const Vec3 p = o + d * t;
    return (p - clampToBox(p)).length();
}

double tinyDistance(double base, const Vec3& lo, const Vec3& hi) {
    const float reach = std::max({std::abs(lo.x), std::abs(lo.y), std::abs(lo.z), std::abs(hi.x), std::abs(hi.y),
                                  std::abs(hi.z)});
    return 1e-6 * (base + double(reach));
}

}  // namespace

VrlImportance::VrlImportance(const Scene& scene, const LightTree& tree, float minimumDistanceFraction)
    : scene_(scene), tree_(tree), fraction_(minimumDistanceFraction) {
    Rgb maxSigmaS(0.0f);
    for (const auto& m : scene.media()) {
        for (int c = 0; c < 3; ++c) maxSigmaS[c] = std::max(maxSigmaS[c], m.sigmaS()[c]);
        const Rgb sigmaT = m.sigmaT();
        sigmaTMin_.push_back(std::min({sigmaT.x, sigmaT.y, sigmaT.z}));
        convex_.push_back(m.boundaryConvex());
        isotropic_.push_back(m.phase().isIsotropic());
    }
    if (tree.empty()) return;
    const auto& nodes = tree.nodes();
    leafCount_ = int32_t(tree.vrls().size());
    indexBits_ = std::max(1, int(std::bit_width(uint32_t(nodes.size() - 1))));
    indexMask_ = int32_t((uint32_t(1) << indexBits_) - 1);
    const int mediumBits = 31 - indexBits_;
    const bool packMedia = mediumBits > 0 && scene.media().size() + 1 < (size_t(1) << mediumBits);
    const auto child = [&](int32_t index) {
        const LightTreeNode& n = nodes[size_t(index)];
        const Rgb sigmaS = n.medium >= 0 ? scene.media()[size_t(n.medium)].sigmaS() : maxSigmaS;
        Child c;
        for (int a = 0; a < 3; ++a) c.lo[a] = n.box.min[a], c.hi[a] = n.box.max[a];
        c.weight = luminance(n.fluxLength * sigmaS);
        const uint32_t code = packMedia ? uint32_t(n.medium + 1) : 0u;
        c.packed = int32_t(uint32_t(index) | (code << indexBits_));
        return c;
    };
    pairs_.resize(nodes.size() - size_t(leafCount_));
    for (size_t i = size_t(leafCount_); i < nodes.size(); ++i)
        pairs_[i - size_t(leafCount_)] = Pair{{child(nodes[i].left), child(nodes[i].right)}};
}

const VrlImportance::Pair& VrlImportance::pair(int32_t parent) const {
    const Pair& p = pairs_[size_t(parent - leafCount_)];
    // The next level's records, while this one's importances are computed: a
    // descent is otherwise a chain of cache misses.
    for (const Child& c : p.child) {
        const int32_t node = nodeOf(c);
        if (node >= leafCount_) __builtin_prefetch(&pairs_[size_t(node - leafCount_)]);
    }
    return p;
}

VrlImportance::SegmentQuery VrlImportance::prepare(const CameraSegment& segment) const {
    SegmentQuery q;
    q.origin = segment.origin;
    q.direction = segment.direction;
    q.absDirection = Vec3(std::abs(segment.direction.x), std::abs(segment.direction.y), std::abs(segment.direction.z));
    q.length = double(segment.length);
    q.tinyBase = 1.0 + double(segment.origin.length());
    q.medium = segment.medium;
    if (segment.medium >= 0) {
        const size_t m = size_t(segment.medium);
        q.sigmaTMin = convex_[m] ? sigmaTMin_[m] : 0.0f;
        q.anisotropic = !isotropic_[m];
    }
    return q;
}

ChildImportances VrlImportance::children(int32_t parent, const SegmentQuery& query) const {
    const Pair& p = pair(parent);
    return {{nodeOf(p.child[0]), nodeOf(p.child[1])},
            {segmentImportance(p.child[0], query), segmentImportance(p.child[1], query)}};
}

double VrlImportance::segmentImportance(const Child& c, const SegmentQuery& q) const {
    const double w = double(c.weight);
    if (!(w > 0.0)) return 0.0;
    const Vec3 lo(c.lo[0], c.lo[1], c.lo[2]), hi(c.hi[0], c.hi[1], c.hi[2]);
    const float hBox = approximateDistanceLineBox(q.origin, q.direction, lo, hi);
    const Vec3 extent = hi - lo;
    const double h = std::max({double(hBox), double(fraction_ * extent.length()), tinyDistance(q.tinyBase, lo, hi)});
    // The box's projection onto the line, and the foot point nearest the segment's middle.
    const Vec3 centre = (lo + hi) * 0.5f;
    const double tc = double(q.direction.dot(centre - q.origin));
    const double r = 0.5 * double(q.absDirection.dot(extent));
    const double S = q.length;
    const double t = std::clamp(0.5 * S, tc - r, tc + r);
    // The angle thetaB - thetaA = atan(b) + atan(a), a = t / h, b = (S - t) / h, is
    // atan2(a + b, 1 - a b) (a + b = S / h > 0: in (0, pi)), and the tangent of its
    // middle direction, tan((thetaA + thetaB) / 2) = tan((atan b - atan a) / 2), is
    // (b - a) / (sqrt((1 + a^2)(1 + b^2)) + 1 + a b) (tan(x/2) = sin x / (1 + cos x)).
    const double a = t / h, b = (S - t) / h;
    const double angle = positiveAtan2(S / h, 1.0 - a * b);
    const int medium = mediumOf(c);
    double transmittance = 1.0;
    if (q.sigmaTMin > 0.0f && medium == q.medium)
        transmittance = std::max(double(std::exp(-q.sigmaTMin * hBox)), kTransmittanceBoundFloor);
    double importance = w * transmittance * angle / h;
    // Henyey-Greenstein media: the phase functions towards the point u of the camera
    // line in the middle of the subtended angle, relative to isotropic (4 pi)^2 f f:
    // the camera side for every node whose box is small seen from there, the VRL side
    // for single VRLs (an inner node's VRL directions are unknown: isotropic).
    if (q.anisotropic || medium < 0 || !isotropic_[size_t(medium)]) {
        const double middleTangent = (b - a) / (std::sqrt((1.0 + a * a) * (1.0 + b * b)) + 1.0 + a * b);
        const Vec3 toU = q.origin + q.direction * float(t + h * middleTangent) - centre;
        const float distance = toU.length();
        if (distance > extent.length() && distance > 0.0f) {
            const Vec3 toUnit = toU / distance;
            const HomogeneousMedium& cameraMedium = scene_.media()[size_t(q.medium)];
            importance *= 4.0 * M_PI * double(cameraMedium.phase().evalCosine(-toUnit.dot(q.direction)));
            const int32_t node = nodeOf(c);
            if (node < leafCount_ && medium >= 0)
                importance *= 4.0 * M_PI *
                              double(scene_.media()[size_t(medium)].phase().eval(tree_.vrls()[size_t(node)].direction,
                                                                                  toUnit));
        }
    }
    return importance;
}

VrlImportance::SurfaceQuery VrlImportance::prepare(const CameraPathSurface& x) const {
    SurfaceQuery q;
    q.position = x.hit.position;
    const SceneShape& shape = scene_.shapes()[x.hit.shape];
    q.reflectsOnly = shape.bsdf.kind() != BsdfDescription::Kind::RoughDielectric;
    q.changesMedium = shape.changesMedium;
    q.facingNormal = x.hit.geometricNormal * (x.wo.dot(x.hit.geometricNormal) >= 0.0f ? 1.0f : -1.0f);
    q.shadingNormal = x.hit.shadingNormal;
    q.tinyBase = 1.0 + double(x.hit.position.length());
    q.medium = x.medium;
    return q;
}

ChildImportances VrlImportance::children(int32_t parent, const SurfaceQuery& query) const {
    const Pair& p = pair(parent);
    return {{nodeOf(p.child[0]), nodeOf(p.child[1])},
            {surfaceImportance(p.child[0], query), surfaceImportance(p.child[1], query)}};
}

double VrlImportance::surfaceImportance(const Child& c, const SurfaceQuery& q) const {
    const double w = double(c.weight);
    if (!(w > 0.0)) return 0.0;
    const Imath::Box3f box(Vec3(c.lo[0], c.lo[1], c.lo[2]), Vec3(c.hi[0], c.hi[1], c.hi[2]));
    const Vec3& p = q.position;
    const double tiny = tinyDistance(q.tinyBase, box.min, box.max);
    // Wholly behind a reflecting surface (with the bound's rounding slack): exactly 0.
    if (q.reflectsOnly && signedDistanceRange(box, q.facingNormal, p).second < -8.0 * tiny) return 0.0;
    const double dBox = distancePointBox(p, box);
    const double d = std::max({dBox, double(fraction_) * double((box.max - box.min).length()), tiny});
    const auto [lo, hi] = signedDistanceRange(box, q.shadingNormal, p);
    const double cosine = std::clamp(std::max(std::abs(lo), std::abs(hi)) / std::max(dBox, tiny), 1e-3, 1.0);
    const int medium = mediumOf(c);
    double transmittance = 1.0;
    if (medium >= 0 && medium == q.medium && q.reflectsOnly && !q.changesMedium && convex_[size_t(medium)])
        transmittance = std::max(std::exp(-double(sigmaTMin_[size_t(medium)]) * dBox), kTransmittanceBoundFloor);
    // A single VRL in an anisotropic medium: its phase function towards x (4 pi f_V).
    double phase = 1.0;
    const int32_t node = nodeOf(c);
    if (node < leafCount_ && medium >= 0 && !isotropic_[size_t(medium)]) {
        const Vrl& vrl = tree_.vrls()[size_t(node)];
        const Vec3 toX = p - (vrl.origin + vrl.direction * (0.5f * vrl.length));
        const float length = toX.length();
        if (length > 0.0f)
            phase = 4.0 * M_PI * double(scene_.media()[size_t(medium)].phase().eval(vrl.direction, toX / length));
    }
    return w * cosine * transmittance * phase / (d * d);
}

}  // namespace vrl
