#include "render/vrl/vrl_surface_estimator.h"

#include "render/scene/scene.h"
#include "render/vrl/vrl_estimator.h"

#include <algorithm>

namespace vrl {

VrlSurfaceEstimator::VrlSurfaceEstimator(const Scene& scene, int samplesPerVrl)
    : scene_(scene), samplesPerVrl_(std::max(1, samplesPerVrl)) {}

Rgb VrlSurfaceEstimator::contribution(const Vrl& vrl, const CameraPathSurface& x, Rng& rng) const {
    if (!(vrl.length > 0.0f)) return Rgb(0.0f);
    Rgb sum(0.0f);
    for (int i = 0; i < samplesPerVrl_; ++i) sum += sampleOnce(vrl, x, rng);
    return sum / float(samplesPerVrl_);
}

Rgb VrlSurfaceEstimator::sampleOnce(const Vrl& vrl, const CameraPathSurface& x, Rng& rng) const {
    const Vec3& p = x.hit.position;
    const DistanceSample vs = sampleEquiangular(vrl.origin, vrl.direction, vrl.length, p, rng.next());
    if (!(vs.pdf > 0.0f)) return Rgb(0.0f);
    const Vec3 v = vrl.origin + vrl.direction * vs.t;
    const Vec3 toV = v - p;
    const float r2 = toV.length2();
    if (!(r2 > 0.0f)) return Rgb(0.0f);
    const float r = std::sqrt(r2);
    const Vec3 wi = toV / r;
    const Rgb f = x.bsdf.eval(wi, TransportMode::Radiance);
    if (isBlack(f)) return Rgb(0.0f);
    const HomogeneousMedium& medium = scene_.media()[vrl.medium];
    const float phase = medium.phase().eval(vrl.direction, -wi);
    const int towards = scene_.mediumAfter(x.hit, wi, x.medium);
    // Inside one medium whose segments nothing can block: no visibility ray.
    Rgb between;
    if (towards == vrl.medium && !scene_.mediumNeedsVisibility(towards)) {
        between = medium.transmittance(r);
    } else {
        // The visibility ray leaves from an offset origin (1e-4 of the triangle's
        // scale); the stretch it skips is in `towards` too: add its transmittance.
        const Vec3 origin = Scene::offsetOrigin(x.hit, wi);
        between = scene_.transmittance(origin, v, towards);
        if (towards >= 0 && !isBlack(between))
            between *= scene_.media()[towards].transmittance(r - (v - origin).length());
    }
    if (isBlack(between)) return Rgb(0.0f);
    const double scale = double(phase) / (double(r2) * double(vs.pdf));
    return vrl.flux * medium.sigmaS() * f * between * x.throughput * float(scale);
}

}  // namespace vrl
