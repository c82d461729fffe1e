#include "render/lightcuts/bounds/surface_cluster_bound.h"

#include "render/core/distance.h"
#include "render/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vrl {

namespace {

constexpr double kRoundingMargin = 1.001;  // as cluster_bound.cpp

// Largest value of the phase function over all angles.
float phaseMaximum(const PhaseFunction& phase) {
    if (phase.isIsotropic()) return float(kInv4Pi);
    const double g = std::abs(double(phase.g()));
    return float((1.0 + g) / (4.0 * M_PI * (1.0 - g) * (1.0 - g)));
}

}  // namespace

SurfaceClusterBound::SurfaceClusterBound(const Scene& scene, const LightTree& tree, ClusterBoundSettings settings,
                                         const DirectionCones* cones, const LeafSegments* leaves)
    : scene_(scene), tree_(tree), settings_(settings) {
    leaves_ = LeafSegments::shareOrBuild(leaves, tree, ownedLeaves_);
    for (const auto& m : scene.media()) {
        for (int c = 0; c < 3; ++c) maxSigmaS_[c] = std::max(maxSigmaS_[c], m.sigmaS()[c]);
        maxPhase_ = std::max(maxPhase_, phaseMaximum(m.phase()));
    }
    if (DirectionCones::neededFor(scene.media())) cones_ = DirectionCones::shareOrBuild(cones, tree, ownedCones_);
}

double SurfaceClusterBound::phaseBound(int32_t index, const Vec3& x, double slack, double d) const {
    const LightTreeNode& node = tree_.nodes()[index];
    const HomogeneousMedium* vrlMedium = node.medium >= 0 ? &scene_.media()[node.medium] : nullptr;
    if (!cones_) return vrlMedium ? phaseMaximum(vrlMedium->phase()) : maxPhase_;  // isotropic: 1/(4 pi)
    double cosLow = -1.0, cosHigh = 1.0;
    const Imath::V3d centre = (Imath::V3d(node.box.min) + Imath::V3d(node.box.max)) * 0.5;
    const Imath::V3d toX = Imath::V3d(x) - centre;
    const double distance = toX.length();
    const double radius = 0.5 * (Imath::V3d(node.box.max) - Imath::V3d(node.box.min)).length() + slack;
    const DirectionCone& cone = (*cones_)[index];
    if (distance > radius && !cone.isSphere()) {
        // Cosines of theta -+ (alpha + beta) by the addition formulas (one sincos); the
        // rounding widening applies to the cosines (a cosine moves by at most its angle).
        const Imath::V3d a = Imath::V3d(cone.axis).normalized();
        const double cosTheta = std::clamp(a.dot(toX) / distance, -1.0, 1.0);
        const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
        const double sinBeta = radius / distance, cosBeta = std::sqrt(std::max(0.0, 1.0 - sinBeta * sinBeta));
        const double alpha = cone.halfAngle, sinAlpha = std::sin(alpha), cosAlpha = std::cos(alpha);
        const double cosSpread = cosAlpha * cosBeta - sinAlpha * sinBeta;  // spread = alpha + beta
        const double sinSpread = sinAlpha * cosBeta + cosAlpha * sinBeta;
        const double widen = 2.0 * slack / d + 1e-6 + 1e-12;
        // theta - spread <= 0 exactly when cos theta >= cos spread (both in [0, pi] when spread <= pi).
        const bool spreadBelowPi = sinSpread >= 0.0 || cosSpread > 0.0;
        if (spreadBelowPi) {
            cosHigh = cosTheta >= cosSpread ? 1.0 : std::min(1.0, cosTheta * cosSpread + sinTheta * sinSpread + widen);
            // theta + spread >= pi exactly when cos theta <= -cos spread.
            cosLow = cosTheta <= -cosSpread ? -1.0 : std::max(-1.0, cosTheta * cosSpread - sinTheta * sinSpread - widen);
        }
    }
    double high = 0.0;
    if (vrlMedium)
        high = vrlMedium->phase().valueRange(cosLow, cosHigh).high;
    else
        for (const auto& m : scene_.media()) high = std::max(high, m.phase().valueRange(cosLow, cosHigh).high);
    return high;
}

bool SurfaceClusterBound::provenFor(const Bsdf& bsdf, const ClusterBoundSettings& settings) {
    return bsdf.lambertianBound(Vec2(0.0f, 0.0f)).has_value() ||
           (settings.glossyBound == GlossyBound::Cones && bsdf.hasConeBound());
}

std::optional<Rgb> SurfaceClusterBound::coneBoundTowardsBox(const CameraPathSurface& x, const Imath::Box3f& box,
                                                            double d, double slack) {
    // The cone of directions from x to the box. Where x lies outside the box, those
    // directions are the spherically convex hull of the directions to its corners, and
    // a cap of half-angle below pi/2 (a convex set) that holds the corners holds them
    // all. Axis: towards the box's centre. (Where x lies inside it, possible for small
    // nodes, whose d is the distance to their segments, the corner opposite the centre
    // in every coordinate is at 90 degrees or more from the axis: every direction.)
    // Widened for the rounding of the sample points (within `slack` of the box, at
    // distance >= d) and of the directions to them. (Bounding a wide cone's box by its
    // eight octants instead cut staircase's part-(c) evaluations by 4.5% and made the
    // render 1.8x slower: the bounds cost more than the evaluations they saved.)
    const Imath::V3d p(x.hit.position);
    const Imath::V3d axis = ((Imath::V3d(box.min) + Imath::V3d(box.max)) * 0.5 - p).normalized();
    double cosWidest = 1.0;
    for (int corner = 0; corner < 8; ++corner) {
        const Imath::V3d q(corner & 1 ? box.max.x : box.min.x, corner & 2 ? box.max.y : box.min.y,
                           corner & 4 ? box.max.z : box.min.z);
        const Imath::V3d to = q - p;
        const double length = to.length();
        if (length > 0.0) cosWidest = std::min(cosWidest, axis.dot(to) / length);
    }
    const double halfAngle = std::acos(std::clamp(cosWidest, -1.0, 1.0)) + 2.0 * slack / d + 1e-6;
    if (!(d > 0.0) || !(halfAngle < 0.5 * M_PI) || !std::isfinite(axis.x + axis.y + axis.z))
        return x.bsdf.coneBound(Vec3(0.0f, 0.0f, 1.0f), 4.0);  // every direction
    return x.bsdf.coneBound(Vec3(float(axis.x), float(axis.y), float(axis.z)), halfAngle);
}

double SurfaceClusterBound::minimumDistance(int32_t index, const Vec3& x) const {
    const LightTreeNode& node = tree_.nodes()[index];
    if (node.vrlCount > settings_.exactDistanceBelow) return distancePointBox(x, node.box);
    return leaves_->minDistanceToPoint(index, x);
}

Rgb SurfaceClusterBound::reflectionTowardsBox(const CameraPathSurface& x, const Bsdf& bsdf, const Imath::Box3f& box,
                                              double d, double slack, const ClusterBoundSettings& settings,
                                              const Rgb* inheritedGlossy) {
    const Vec3& p = x.hit.position;
    // Reflection only on wo's geometric side: a box wholly behind gives nothing.
    const bool reflectsOnly = bsdf.kind() != BsdfDescription::Kind::RoughDielectric;
    const float side = x.wo.dot(x.hit.geometricNormal) >= 0.0f ? 1.0f : -1.0f;
    if (reflectsOnly && signedDistanceRange(box, x.hit.geometricNormal * side, p).second < -slack) return Rgb(0.0f);

    Rgb fCos;
    const std::optional<Rgb> lambert = x.bsdf.lambertianBound();  // x's lookups: no texture read per node
    if (lambert) {
        const auto [lo, hi] = signedDistanceRange(box, x.hit.shadingNormal, p);
        const double cosine = std::min(1.0, (std::max(std::abs(lo), std::abs(hi)) + slack) / d);
        fCos = *lambert * float(cosine);
    } else if (inheritedGlossy) {
        fCos = *inheritedGlossy;
    } else if (const std::optional<Rgb> cone = settings.glossyBound == GlossyBound::Cones
                                                     ? coneBoundTowardsBox(x, box, d, slack)
                                                     : std::nullopt) {
        fCos = *cone;
    } else {
        // Glossy: the largest f|cos| towards the box's corners, its centre and its
        // point nearest the mirror direction (where a lobe peaks), with a margin (a heuristic).
        const Vec3 n = x.hit.shadingNormal * (x.wo.dot(x.hit.shadingNormal) >= 0.0f ? 1.0f : -1.0f);
        const Vec3 mirror = n * (2.0f * x.wo.dot(n)) - x.wo;
        const float along = std::max(0.0f, mirror.dot(box.center() - p));
        const Vec3 onMirror = p + mirror * along;
        const Vec3 nearMirror(std::clamp(onMirror.x, box.min.x, box.max.x),
                              std::clamp(onMirror.y, box.min.y, box.max.y),
                              std::clamp(onMirror.z, box.min.z, box.max.z));
        Rgb largest(0.0f);
        for (int corner = 0; corner < 10; ++corner) {
            const Vec3 q = corner == 9   ? nearMirror
                           : corner == 8 ? box.center()
                                         : Vec3(corner & 1 ? box.max.x : box.min.x,
                                                corner & 2 ? box.max.y : box.min.y,
                                                corner & 4 ? box.max.z : box.min.z);
            const Vec3 to = q - p;
            const float length = to.length();
            if (!(length > 0.0f)) continue;
            const Rgb f = x.bsdf.eval(to / length, TransportMode::Radiance);
            for (int c = 0; c < 3; ++c) largest[c] = std::max(largest[c], f[c]);
        }
        fCos = largest * settings.glossyMargin;
    }
    return fCos;
}

double SurfaceClusterBound::slackOf(const Imath::Box3f& box, const Vec3& p) {
    const float reach = std::max({std::abs(box.min.x), std::abs(box.min.y), std::abs(box.min.z), std::abs(box.max.x),
                                  std::abs(box.max.y), std::abs(box.max.z)});
    return 8.0 * 0x1p-24 * (double(p.length()) + reach);
}

Rgb SurfaceClusterBound::bound(int32_t index, const CameraPathSurface& x, bool* xInsideNode, Rgb* factor,
                               const double* distance) const {
    const Imath::Box3f& box = tree_.nodes()[index].box;
    const double slack = slackOf(box, x.hit.position);
    const double d = distance ? *distance : minimumDistance(index, x.hit.position) - slack;
    if (xInsideNode) *xInsideNode = !(d > 0.0);
    return boundAt(index, x, d, slack, nullptr, factor);
}

Rgb SurfaceClusterBound::cheapBound(int32_t index, const CameraPathSurface& x, bool* xInsideNode,
                                    const Rgb* inheritedGlossy, Rgb* factor, bool* tight, double* distance) const {
    const Vec3& p = x.hit.position;
    const double slack = slackOf(tree_.nodes()[index].box, p);
    const double d = minimumDistance(index, p) - slack;
    if (distance) *distance = d;
    if (xInsideNode) *xInsideNode = !(d > 0.0);
    const bool glossyInherited = inheritedGlossy && !x.bsdf.lambertianBound().has_value();
    if (tight) *tight = !glossyInherited;
    return boundAt(index, x, d, slack, glossyInherited ? inheritedGlossy : nullptr, factor);
}

Rgb SurfaceClusterBound::boundAt(int32_t index, const CameraPathSurface& x, double d, double slack,
                                 const Rgb* inheritedGlossy, Rgb* factor) const {
    const LightTreeNode& node = tree_.nodes()[index];
    const Vec3& p = x.hit.position;
    if (!(d > 0.0)) return Rgb(std::numeric_limits<float>::infinity());

    const SceneShape& shape = scene_.shapes()[x.hit.shape];
    const bool reflectsOnly = shape.bsdf.kind() != BsdfDescription::Kind::RoughDielectric;
    const Rgb fCos = reflectionTowardsBox(x, shape.bsdf, node.box, d, slack, settings_, inheritedGlossy);
    if (factor) *factor = fCos;
    if (isBlack(fCos)) return Rgb(0.0f);

    const HomogeneousMedium* vrlMedium = node.medium >= 0 ? &scene_.media()[node.medium] : nullptr;
    const Rgb sigmaS = vrlMedium ? vrlMedium->sigmaS() : maxSigmaS_;
    const double phase = phaseBound(index, p, slack, d);
    if (!std::isfinite(phase)) return Rgb(std::numeric_limits<float>::infinity());
    Rgb between(1.0f);
    if (vrlMedium && node.medium == x.medium && reflectsOnly && !shape.changesMedium && vrlMedium->boundaryConvex())
        between = vrlMedium->transmittance(float(d));
    // Phi_C (theta_B - theta_A) / h <= Phi_C min(L_rep / d^2, pi / d) (header), per channel.
    const double inverse = 1.0 / d;
    const auto along = [&](int c) {
        return float(std::min(double(node.fluxLength[c]) * inverse, M_PI * double(node.clusterFlux[c])) * inverse);
    };
    const Rgb overDistance(along(0), along(1), along(2));
    return overDistance * sigmaS * fCos * between * x.throughput * float(kRoundingMargin * phase);
}

}  // namespace vrl
