#include "render/lightcuts/cuts/vpl_lightcuts_estimator.h"

#include "render/core/distance.h"
#include "render/lightcuts/cuts/cut_walk.h"
#include "render/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace vrl {

namespace {
constexpr double kRoundingMargin = 1.001;
constexpr float kInv4PiF = 0.0795774715459476678f;
}  // namespace

VplLightcutsEstimator::VplLightcutsEstimator(const Scene& scene, const LightTree& tree, CutSettings settings,
                                             int distanceSamples)
    : scene_(scene), tree_(tree), settings_(settings), distanceSamples_(distanceSamples) {
    if (distanceSamples_ < 1) throw std::invalid_argument("VPL Lightcuts needs at least one distance sample");
}

Rgb VplLightcutsEstimator::vplContribution(const Vrl& vpl, const Rgb& flux, const Vec3& x, const Vec3& toCamera,
                                           int medium) const {
    return vrl::vplContribution(scene_, vpl, flux, x, toCamera, medium);
}

Rgb VplLightcutsEstimator::bound(int32_t index, const Vec3& x, int medium) const {
    const LightTreeNode& node = tree_.nodes()[index];
    const float reach = std::max({std::abs(node.box.min.x), std::abs(node.box.min.y), std::abs(node.box.min.z),
                                  std::abs(node.box.max.x), std::abs(node.box.max.y), std::abs(node.box.max.z)});
    const double slack = 8.0 * 0x1p-24 * (double(x.length()) + reach);
    const double d = distancePointBox(x, node.box) - slack;
    if (!(d > 0.0)) return Rgb(std::numeric_limits<float>::infinity());
    const HomogeneousMedium& mediumX = scene_.media()[medium];
    bool isotropic = mediumX.phase().isIsotropic();
    if (node.medium >= 0)
        isotropic = isotropic && scene_.media()[node.medium].phase().isIsotropic();
    else
        for (const auto& m : scene_.media()) isotropic = isotropic && m.phase().isIsotropic();
    double phase = double(kInv4PiF) * double(kInv4PiF);
    if (!isotropic) phase *= 1.0 + settings_.bound.anisotropyEpsilon;
    Rgb between(1.0f);
    if (node.medium == medium && mediumX.boundaryConvex()) between = mediumX.transmittance(float(d));
    return node.clusterFlux * between * float(kRoundingMargin * phase / (d * d));
}

Rgb VplLightcutsEstimator::gather(const Vec3& x, const Vec3& toCamera, int medium, CutStatistics& statistics) const {
    if (tree_.empty()) return Rgb(0.0f);
    struct Visitor {
        const VplLightcutsEstimator& self;
        const Vec3& x;
        const Vec3& toCamera;
        int medium;
        Rgb leaf(int32_t i) const {
            const Vrl& vpl = self.tree_.vrls()[self.tree_.nodes()[i].representative];
            return self.vplContribution(vpl, vpl.flux, x, toCamera, medium);
        }
        bool bound(int32_t i, Rgb& b) const {  // x in the node's box: infinite
            b = self.bound(i, x, medium);
            return std::isfinite(b.x + b.y + b.z);
        }
        Rgb estimate(int32_t i) const {
            const LightTreeNode& node = self.tree_.nodes()[i];
            return self.vplContribution(self.tree_.vrls()[node.representative], node.clusterFlux, x, toCamera, medium);
        }
    };
    return walkCut(tree_, settings_, statistics, Visitor{*this, x, toCamera, medium});
}

Rgb VplLightcutsEstimator::estimate(const CameraSegment& segment, Rng& rng, CutStatistics& statistics) const {
    if (tree_.empty()) return Rgb(0.0f);
    const Vec3 toCamera = -segment.direction;
    return integrateAlongSegment(scene_, segment, distanceSamples_, rng, [&](const Vec3& x) {
        return gather(x, toCamera, segment.medium, statistics);
    });
}

}  // namespace vrl
