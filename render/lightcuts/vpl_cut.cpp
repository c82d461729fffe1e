#include "render/lightcuts/vpl_cut.h"

#include "render/core/distance.h"
#include "render/lightcuts/cut_walk.h"
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

Rgb vplContribution(const Scene& scene_, const Vrl& vpl, const Rgb& flux, const Vec3& x, const Vec3& toCamera,
                    int medium) {
    const Vec3 d = x - vpl.origin;
    const float w2 = d.length2();
    if (!(w2 > 0.0f) || !std::isfinite(w2)) return Rgb(0.0f);
    const float w = std::sqrt(w2);
    const Vec3 toX = d / w;
    const HomogeneousMedium& mediumX = scene_.media()[medium];
    const HomogeneousMedium& mediumV = scene_.media()[vpl.medium];
    const float phase = mediumV.phase().eval(vpl.direction, toX) * mediumX.phase().eval(toX, toCamera);
    if (!(phase > 0.0f)) return Rgb(0.0f);
    const Rgb between = vpl.medium == medium && !scene_.mediumNeedsVisibility(medium)
                            ? mediumX.transmittance(w)
                            : scene_.transmittance(x, vpl.origin, medium);
    if (isBlack(between)) return Rgb(0.0f);
    return flux * between * (phase / w2);
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

Rgb integrateAlongSegment(const Scene& scene, const CameraSegment& segment, int distanceSamples, Rng& rng,
                          const std::function<Rgb(const Vec3& x)>& gather) {
    if (!(segment.length > 0.0f) || distanceSamples < 1) return Rgb(0.0f);
    const HomogeneousMedium& medium = scene.media()[segment.medium];
    if (medium.isNonScattering()) return Rgb(0.0f);
    const double sigma = minComponent(medium.sigmaT());
    const double length = segment.length;
    const bool uniform = !(sigma * length > 1e-6);
    const double norm = uniform ? length : -std::expm1(-sigma * length) / sigma;  // integral of exp(-sigma u)
    Rgb sum(0.0f);
    for (int i = 0; i < distanceSamples; ++i) {
        const double xi = (i + rng.nextDouble()) / distanceSamples;
        const double u = uniform ? xi * length
                                 : std::min(length, -std::log1p(xi * std::expm1(-sigma * length)) / sigma);
        const double pdf = (uniform ? 1.0 : std::exp(-sigma * u)) / norm;
        if (!(pdf > 0.0) || !std::isfinite(pdf)) continue;
        const Rgb in = gather(segment.origin + segment.direction * float(u));
        sum += in * medium.transmittance(float(u)) * float(1.0 / (pdf * distanceSamples));
    }
    return sum * medium.sigmaS() * segment.throughputBefore;
}

Rgb VplLightcutsEstimator::estimate(const CameraSegment& segment, Rng& rng, CutStatistics& statistics) const {
    if (tree_.empty()) return Rgb(0.0f);
    const Vec3 toCamera = -segment.direction;
    return integrateAlongSegment(scene_, segment, distanceSamples_, rng, [&](const Vec3& x) {
        return gather(x, toCamera, segment.medium, statistics);
    });
}

VplEstimator::VplEstimator(const Scene& scene, const std::vector<Vrl>& vpls, int distanceSamples)
    : scene_(scene), vpls_(vpls), distanceSamples_(distanceSamples) {
    if (distanceSamples_ < 1) throw std::invalid_argument("VPLs need at least one distance sample");
}

Rgb VplEstimator::estimate(const CameraSegment& segment, Rng& rng) const {
    if (vpls_.empty()) return Rgb(0.0f);
    const Vec3 toCamera = -segment.direction;
    return integrateAlongSegment(scene_, segment, distanceSamples_, rng, [&](const Vec3& x) {
        Rgb total(0.0f);
        for (const Vrl& vpl : vpls_) total += vplContribution(scene_, vpl, vpl.flux, x, toCamera, segment.medium);
        return total;
    });
}

}  // namespace vrl
