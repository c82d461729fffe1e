#include "render/lightcuts/cluster_bound.h"

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
constexpr double kPiD = 3.14159265358979323846;

using V3d = Imath::V3d;
V3d toD(const Vec3& v) { return {v.x, v.y, v.z}; }

struct AngleRange {
    double low, high;  // in [0, pi]
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
                           const DirectionCones* cones)
    : scene_(scene), tree_(tree), settings_(settings), leaves_(tree) {
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
    // The angle at v: within the VRL cone's polar spread of toU's polar angles.
    const AngleRange polar{std::max(0.0, std::acos(polarHigh) - widen), std::min(kPiD, std::acos(polarLow) + widen)};
    const double alpha = vrlCone.isSphere() ? kPiD : double(vrlCone.halfAngle);
    const double thetaA = angleBetween(vrlCone.axis, segment.direction);  // atan2: exact for a float-rounded axis
    const AngleRange aPolar{std::max(0.0, thetaA - alpha - 1e-7), std::min(kPiD, thetaA + alpha + 1e-7)};
    const double lowest = aPolar.low + polar.low, highest = aPolar.high + polar.high;
    const double vAngleLow = std::max({0.0, polar.low - aPolar.high, aPolar.low - polar.high});
    const double vAngleHigh = highest < kPiD ? highest : lowest > kPiD ? 2.0 * kPiD - lowest : kPiD;
    const double vLow = std::cos(vAngleHigh), vHigh = std::cos(vAngleLow);
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
    double best = std::numeric_limits<double>::infinity();
    const auto starts = leaves_.starts(index), ends = leaves_.ends(index);
    for (size_t k = 0; k < starts.size(); ++k)
        best = std::min(best, distanceLineSegment(segment.origin, segment.direction, starts[k], ends[k]));
    return best;
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
    // T_r(w) <= T_r(h_min) only if the segment between u and v stays in this one convex medium.
    Rgb between(1.0f);
    if (node.medium == segment.medium && cameraMedium.boundaryConvex()) between = cameraMedium.transmittance(float(h));
    // The node is estimated by its representative with flux Phi_C: the bound's
    // Phi L factor is Phi_C L_rep = the node's flux x length (<= Phi_C L_max, Eq. 11's).
    const double scale = kRoundingMargin * phase * span / h;
    return node.fluxLength * sigmaSV * cameraMedium.sigmaS() * segment.throughputBefore * between * float(scale);
}

}  // namespace vrl
