#include "render/lightcuts/cluster_bound.h"

#include "render/core/distance.h"
#include "render/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vrl {

namespace {
// Float noise in the estimator's own arithmetic (rounded sample points): the bound
// carries this relative margin.
constexpr double kRoundingMargin = 1.001;
}  // namespace

ClusterBound::ClusterBound(const Scene& scene, const LightTree& tree, ClusterBoundSettings settings)
    : scene_(scene), tree_(tree), settings_(settings), leaves_(tree) {
    for (const auto& m : scene.media()) {
        for (int c = 0; c < 3; ++c) maxSigmaS_[c] = std::max(maxSigmaS_[c], m.sigmaS()[c]);
    }
}

double ClusterBound::minimumDistance(int32_t index, const CameraSegment& segment) const {
    const LightTreeNode& node = tree_.nodes()[index];
    if (node.vrlCount > settings_.exactDistanceBelow)
        return distanceLineBox(segment.origin, segment.direction, node.box);
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
    const HomogeneousMedium* vrlMedium = node.medium >= 0 ? &scene_.media()[node.medium] : nullptr;
    const Rgb sigmaSV = vrlMedium ? vrlMedium->sigmaS() : maxSigmaS_;
    const bool isotropic = cameraMedium.phase().isIsotropic() && (!vrlMedium || vrlMedium->phase().isIsotropic()) &&
                           (vrlMedium || std::all_of(scene_.media().begin(), scene_.media().end(),
                                                     [](const auto& m) { return m.phase().isIsotropic(); }));
    double phase = double(kInv4Pi) * double(kInv4Pi);
    if (!isotropic) phase *= 1.0 + settings_.anisotropyEpsilon;
    // T_r(w) <= T_r(h_min) only if the segment between u and v stays in this one convex medium.
    Rgb between(1.0f);
    if (node.medium == segment.medium && cameraMedium.boundaryConvex()) between = cameraMedium.transmittance(float(h));
    // The node is estimated by its representative with flux Phi_C: the bound's
    // Phi L factor is Phi_C L_rep = the node's flux x length (<= Phi_C L_max, Eq. 11's).
    const double scale = kRoundingMargin * phase * maxSubtendedAngle(segment.length, h) / h;
    return node.fluxLength * sigmaSV * cameraMedium.sigmaS() * segment.throughputBefore * between * float(scale);
}

}  // namespace vrl
