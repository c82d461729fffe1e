#include "render/vrl/surface_vpl_estimator.h"

#include "render/vrl/vrl_estimator.h"

#include <algorithm>
#include <cmath>

namespace vrl {

Rgb SurfaceVplEstimator::contribution(const SurfaceVpl& vpl, const PreparedBsdf& atVpl, const Rgb& flux,
                                      const CameraSegment& segment, Rng& rng) const {
    if (!(segment.length > 0.0f) || segment.medium < 0) return Rgb(0.0f);
    const HomogeneousMedium& medium = scene_.media()[size_t(segment.medium)];
    if (medium.isNonScattering()) return Rgb(0.0f);
    const DistanceSample us = sampleEquiangular(segment.origin, segment.direction, segment.length, vpl.position, rng.next());
    if (!(us.pdf > 0.0f)) return Rgb(0.0f);
    const Vec3 u = segment.origin + segment.direction * us.t;
    const Vec3 toU = u - vpl.position;
    const float r2 = toU.length2();
    if (!(r2 > 0.0f) || !std::isfinite(r2)) return Rgb(0.0f);
    const float r = std::sqrt(r2);
    const Vec3 w = toU / r;
    const SurfaceHit hit = surfaceHitOf(vpl);
    const Rgb f = atVpl.eval(w, TransportMode::Importance);
    if (isBlack(f)) return Rgb(0.0f);
    const float phase = medium.phase().eval(w, -segment.direction);
    if (!(phase > 0.0f)) return Rgb(0.0f);
    const int towards = scene_.mediumAfter(hit, w, vpl.medium);
    // The visibility ray leaves from an offset origin (1e-4 of the triangle's
    // scale); the transmittance is rescaled from its length to r, T(r) / T(|u - origin|),
    // which exceeds 1 where u lies closer to the offset origin than to y (u just
    // above the surface near y): clamping that at 1 biased such points low.
    const Vec3 origin = Scene::offsetOrigin(hit, w);
    Rgb between = scene_.transmittance(origin, u, towards);
    if (towards >= 0 && !isBlack(between))
        between *= scene_.media()[size_t(towards)].transmittance(r - (u - origin).length());
    if (isBlack(between)) return Rgb(0.0f);
    const double scale = double(phase) / (double(r2) * double(us.pdf));
    return flux * f * between * medium.sigmaS() * medium.transmittance(us.t) * segment.throughputBefore * float(scale);
}

Rgb SurfaceVplEstimator::contribution(const SurfaceVpl& vpl, const PreparedBsdf& atVpl, const Rgb& flux,
                                      const CameraPathSurface& x, float radius) const {
    if (!lambertianBounded(scene_.shapes()[x.hit.shape].bsdf) || !reflectsBroadly(scene_.shapes()[vpl.shape].bsdf))
        return Rgb(0.0f);
    const Vec3 toX = x.hit.position - vpl.position;
    const float r2 = toX.length2();
    if (!(r2 > 0.0f) || !std::isfinite(r2)) return Rgb(0.0f);
    const float r = std::sqrt(r2);
    const Vec3 w = toX / r;
    const Rgb fx = x.bsdf.eval(-w, TransportMode::Radiance);
    if (isBlack(fx)) return Rgb(0.0f);
    const SurfaceHit y = surfaceHitOf(vpl);
    const Rgb fy = atVpl.eval(w, TransportMode::Importance);
    if (isBlack(fy)) return Rgb(0.0f);
    // Visibility between offset origins at both ends; the stretches they skip lie in
    // the medium between, whose transmittance is taken over the whole distance r.
    const int between = scene_.mediumAfter(y, w, vpl.medium);
    const Vec3 from = Scene::offsetOrigin(y, w), to = Scene::offsetOrigin(x.hit, -w);
    Rgb transmittance = scene_.transmittance(from, to, between);
    if (isBlack(transmittance)) return Rgb(0.0f);
    if (between >= 0) transmittance *= scene_.media()[size_t(between)].transmittance(r - (to - from).length());
    const float clamped = std::max(r2, radius * radius);
    return flux * fy * fx * transmittance * x.throughput * (1.0f / clamped);
}

std::optional<Rgb> SurfaceVplEstimator::reflectionBound(const SurfaceVpl& vpl) const {
    const std::optional<Rgb> lambertian = scene_.shapes()[vpl.shape].bsdf.lambertianBound(vpl.uv);
    if (!lambertian) return std::nullopt;
    const float cosGeometric = std::abs(vpl.direction.dot(vpl.geometricNormal));
    const float cosShading = std::abs(vpl.direction.dot(vpl.shadingNormal));
    if (!(cosGeometric > 0.0f)) return Rgb(0.0f);  // a grazing arrival: eval's correction is 0 (safeDiv)
    return *lambertian * (cosShading / cosGeometric);
}

}  // namespace vrl
