#include "render/lightcuts/bounds/cluster_bound.h"

#include "render/core/distance.h"
#include "render/scene/scene.h"
#include "render/vrl/vrl_estimator.h"

#include <Imath/ImathVec.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace vrl {

namespace {
// Float noise in the estimator's own arithmetic (rounded sample points): the bound
// carries this relative margin.
constexpr double kRoundingMargin = 1.001;

using V3d = Imath::V3d;
V3d toD(const Vec3& v) { return {v.x, v.y, v.z}; }

// An angle in [0, pi] as its cosine and (non-negative) sine.
struct Angle {
    double c, s;
    static Angle ofCosine(double c) { return {c, std::sqrt(std::max(0.0, 1.0 - c * c))}; }
    // The angle of this minus / plus `o` (the caller keeps the result in [0, pi]).
    Angle minus(const Angle& o) const { return {c * o.c + s * o.s, s * o.c - c * o.s}; }
    Angle plus(const Angle& o) const { return {c * o.c - s * o.s, s * o.c + c * o.s}; }
};

// The cosines of the polar angles, from the camera direction omega, of the
// directions u - v (u on the segment, v in the box, at least h from the camera
// line): with s the offset along omega from v's foot point to u and r v's
// distance to the line, cos = s / sqrt(s^2 + r^2), monotone in s and (by s's
// sign) in r; s ranges over
// [-max (v - o).omega, S - min (v - o).omega], r over [h, farthest point of the
// box's bounding sphere]. Returns {lowest, highest} cosine.
std::pair<double, double> polarCosines(const V3d& o, const V3d& omega, double length, const Imath::Box3f& box,
                                       double grow, double h) {
    double centre = 0.0, radius = 0.0, halfDiagonal2 = 0.0;
    V3d toCentre;
    for (int a = 0; a < 3; ++a) {
        const double half = 0.5 * (double(box.max[a]) - double(box.min[a]));
        toCentre[a] = 0.5 * (double(box.min[a]) + double(box.max[a])) - o[a];
        centre += omega[a] * toCentre[a];
        radius += std::abs(omega[a]) * (half + grow);
        halfDiagonal2 += half * half;
    }
    const double rMax = (toCentre - omega * centre).length() + std::sqrt(halfDiagonal2) + 2.0 * grow;
    const double sMin = -(centre + radius) - grow, sMax = length - (centre - radius) + grow;
    const auto cosine = [](double s, double r) { return s / std::sqrt(s * s + r * r); };
    const double low = cosine(sMin, sMin < 0.0 ? h : rMax), high = cosine(sMax, sMax > 0.0 ? h : rMax);
    if (!std::isfinite(low) || !std::isfinite(high)) return {-1.0, 1.0};
    return {std::clamp(low, -1.0, 1.0), std::clamp(high, -1.0, 1.0)};
}

}  // namespace

ClusterBound::ClusterBound(const Scene& scene, const LightTree& tree, ClusterBoundSettings settings,
                           const DirectionCones* cones, const LeafSegments* leaves)
    : scene_(scene), tree_(tree), settings_(settings) {
    leaves_ = LeafSegments::shareOrBuild(leaves, tree, ownedLeaves_);
    for (const auto& m : scene.media()) {
        for (int c = 0; c < 3; ++c) maxSigmaS_[c] = std::max(maxSigmaS_[c], m.sigmaS()[c]);
        allIsotropic_ = allIsotropic_ && m.phase().isIsotropic();
    }
    if (!allIsotropic_ && settings_.hgBound == HgBound::Cones) cones_ = DirectionCones::shareOrBuild(cones, tree, ownedCones_);
}

double ClusterBound::hgConeFactor(int32_t index, const CameraSegment& segment, double h, double slack,
                                  double span) const {
    const LightTreeNode& node = tree_.nodes()[index];
    const DirectionCone& vrlCone = (*cones_)[index];
    // Rounded sample points turn directions by at most about 2 slack / h (and a
    // cosine by at most as much as its angle).
    const double widen = 2.0 * slack / h + 1e-6;
    const V3d o = toD(segment.origin), omega = toD(segment.direction).normalized();
    // Polar cosines of toU about omega; the angle at u is pi minus the polar angle.
    const auto [polarLow, polarHigh] = polarCosines(o, omega, double(segment.length), node.box, slack, h);
    const double uLow = std::max(-1.0, -polarHigh - widen), uHigh = std::min(1.0, -polarLow + widen);
    // The angle at v: within the VRL cone's polar spread of toU's polar angles. Angles
    // in [0, pi] are carried as (cos, sin) and combined by the addition formulas; the
    // rounding widening applies to the cosines (a cosine moves by at most its angle).
    double vLow = -1.0, vHigh = 1.0;
    if (!vrlCone.isSphere()) {
        const Angle theta1 = Angle::ofCosine(polarHigh), theta2 = Angle::ofCosine(polarLow);
        const V3d a = toD(vrlCone.axis).normalized();
        const Angle thetaA{a.dot(omega), a.cross(omega).length()};
        const Angle alpha{std::cos(double(vrlCone.halfAngle)), std::sin(double(vrlCone.halfAngle))};
        // The VRL directions' polar angles: [max(0, thetaA - alpha), min(pi, thetaA + alpha)].
        const Angle aLow = thetaA.c >= alpha.c ? Angle{1.0, 0.0} : thetaA.minus(alpha);
        const Angle aHigh = thetaA.c <= -alpha.c ? Angle{-1.0, 0.0} : thetaA.plus(alpha);
        // Smallest angle: the gap between the two polar intervals (at most one is positive).
        if (theta1.c < aHigh.c)
            vHigh = theta1.minus(aHigh).c;
        else if (aLow.c < theta2.c)
            vHigh = aLow.minus(theta2).c;
        // Largest: the sum of polar angles, or 2 pi minus it, or pi.
        if (aHigh.c > -theta2.c)
            vLow = aHigh.plus(theta2).c;
        else if (aLow.c < -theta1.c)
            vLow = aLow.plus(theta1).c;
        const double margin = widen + 1e-7;
        vHigh = std::min(1.0, vHigh + margin), vLow = std::max(-1.0, vLow - margin);
    }
    PhaseFunction::ValueRange fv{kInfinity, 0.0};
    double slope = 0.0, floatFactor = 1.0;
    const auto extend = [&](const HomogeneousMedium& m) {
        const PhaseFunction::ValueRange r = m.phase().valueRange(vLow, vHigh);
        fv.low = std::min(fv.low, r.low), fv.high = std::max(fv.high, r.high);
        slope = std::max(slope, m.phase().logSlopeBound());
        floatFactor = std::max(floatFactor, m.phase().floatErrorFactor());
    };
    if (node.medium >= 0)
        extend(scene_.media()[node.medium]);
    else
        for (const auto& m : scene_.media()) extend(m);
    const PhaseFunction& phaseU = scene_.media()[segment.medium].phase();
    const PhaseFunction::ValueRange fu = phaseU.valueRange(uLow, uHigh);
    const double high = fv.high * fu.high, low = fv.low * fu.low;
    if (!std::isfinite(high)) return kInfinity;
    // Within its bin, the sample's angles are at most span / (2 kHgBins) (plus rounding)
    // from the bin centre's, where b_k was taken: f(u) f(v) <= smooth b_k.
    const double halfBin = span / (2.0 * VrlEstimator::kHgBins) + widen;
    const double smooth =
        std::exp((slope + phaseU.logSlopeBound()) * halfBin) * floatFactor * phaseU.floatErrorFactor() * (1.0 + 1e-4);
    const double w = VrlEstimator::kHgUniformWeight;
    return high / (w + (1.0 - w) * std::clamp(std::max(low / high, 1.0 / smooth), 0.0, 1.0));
}

double ClusterBound::phaseFactor(int32_t index, const CameraSegment& segment, double h, double slack,
                                 double span) const {
    const LightTreeNode& node = tree_.nodes()[index];
    const double isotropic = double(kInv4Pi) * double(kInv4Pi);
    if (allIsotropic_) return isotropic;
    const HomogeneousMedium& cameraMedium = scene_.media()[segment.medium];
    const bool involvesHg = !cameraMedium.phase().isIsotropic() ||
                            (node.medium >= 0 ? !scene_.media()[node.medium].phase().isIsotropic() : true);
    if (!involvesHg) return isotropic;
    if (settings_.hgBound == HgBound::Epsilon) return isotropic * (1.0 + settings_.anisotropyEpsilon);
    return hgConeFactor(index, segment, h, slack, span);
}

double ClusterBound::minimumDistance(int32_t index, const CameraSegment& segment) const {
    const LightTreeNode& node = tree_.nodes()[index];
    if (node.vrlCount > settings_.exactDistanceBelow) {
        if (settings_.sphereDistanceBeyond > 0.0f) {
            // The bounding sphere's distance is a lower bound of the box's, close to it far away.
            const Imath::V3d centre = (Imath::V3d(node.box.min) + Imath::V3d(node.box.max)) * 0.5;
            const double radius = 0.5 * (Imath::V3d(node.box.max) - Imath::V3d(node.box.min)).length();
            const Imath::V3d omega = Imath::V3d(segment.direction).normalized(), r = centre - Imath::V3d(segment.origin);
            const double sphere = (r - omega * omega.dot(r)).length() - radius;
            if (sphere > double(settings_.sphereDistanceBeyond) * radius) return sphere;
        }
        return distanceLineBox(segment.origin, segment.direction, node.box);
    }
    // Small node: the exact distance from its VRL segments (a contiguous range).
    return leaves_->minDistanceToLine(index, segment.origin, segment.direction);
}

Rgb ClusterBound::bound(int32_t index, const CameraSegment& segment, bool* lineCrossesNode) const {
    const LightTreeNode& node = tree_.nodes()[index];
    // The estimator's sample points are rounded to float: take h_min a few float
    // steps of the coordinates closer, so that the bound holds through rounding.
    const float reach = std::max({std::abs(node.box.min.x), std::abs(node.box.min.y), std::abs(node.box.min.z),
                                  std::abs(node.box.max.x), std::abs(node.box.max.y), std::abs(node.box.max.z)});
    const double slack = 8.0 * 0x1p-24 * (double(segment.origin.length()) + reach);
    const double h = minimumDistance(index, segment) - slack;
    if (lineCrossesNode) *lineCrossesNode = !(h > 0.0);
    if (!(h > 0.0)) return Rgb(std::numeric_limits<float>::infinity());
    const HomogeneousMedium& cameraMedium = scene_.media()[segment.medium];
    const Rgb sigmaSV = node.medium >= 0 ? scene_.media()[node.medium].sigmaS() : maxSigmaS_;
    const double span = maxSubtendedAngle(segment.length, h);
    const double phase = phaseFactor(index, segment, h, slack, span);
    if (!std::isfinite(phase)) return Rgb(std::numeric_limits<float>::infinity());
    // T(u) T_r(w) = exp(-sigma_t (u + w)) <= exp(-sigma_t d_o), d_o the distance from the
    // segment's origin to the box (>= h_min; triangle inequality), only if the segment
    // between u and v stays in this one convex medium.
    Rgb between(1.0f);
    if (node.medium == segment.medium && cameraMedium.boundaryConvex())
        between = cameraMedium.transmittanceBound(std::max(h, distancePointBox(segment.origin, node.box) - slack));
    // The node is estimated by its representative with flux Phi_C: the bound's
    // Phi L factor is Phi_C L_rep = the node's flux x length (<= Phi_C L_max, Eq. 11's).
    const double scale = kRoundingMargin * phase * span / h;
    return node.fluxLength * sigmaSV * cameraMedium.sigmaS() * segment.throughputBefore * between * float(scale);
}

}  // namespace vrl
