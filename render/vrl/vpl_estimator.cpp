#include "render/vrl/vpl_estimator.h"

#include "render/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace vrl {

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
