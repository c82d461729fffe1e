#include "render/integrators/path_tracer.h"

#include "render/core/sampling.h"
#include "render/vrl/camera_segment.h"
#include "render/vrl/surface_vpl_estimator.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace vrl {

DirectLighting sampleDirectLighting(const Scene& scene, const Vec3& point, const SurfaceHit* surface, int medium,
                                    Rng& rng) {
    const EmitterSampler& sampler = scene.emitterSampler();
    if (sampler.empty()) return {};
    const auto [index, probability] = sampler.sample(rng.next());
    const Vec2 u(rng.next(), rng.next());
    const DirectLightSample light = scene.emitters()[index]->sampleDirect(point, u);
    if (isBlack(light.weight)) return {};
    Vec3 origin = point;
    if (surface) {
        origin = Scene::offsetOrigin(*surface, light.direction);
        medium = scene.mediumAfter(*surface, light.direction, medium);
    }
    const Rgb tr = scene.transmittance(origin, light.position, medium);
    if (isBlack(tr)) return {light.direction, Rgb(0.0f)};
    return {light.direction, light.weight * tr / probability, light.pdf * probability, tr};
}

namespace {

// The BSDF strategy's density in the MIS weights is Bsdf::pdf times the chance
// that its ray reaches the light unscattered: free-flight sampling (spectral
// MIS) passes a stretch of transmittance T with probability average(T); a
// stretch crossed by transmittance alone always passes. Both strategies take
// it from the transmittance along their own ray to the same light point, so
// the weights of a path sum to 1 (up to the offset of the shadow ray's ends).
float passProbability(const Rgb& transmittance, bool surely) { return surely ? 1.0f : average(transmittance); }

}  // namespace

Rgb VolumetricPathTracer::radiance(Ray ray, int medium, Rng& rng, const PathStart& start) const {
    Rgb result(0.0f), throughput(1.0f);
    int vertices = start.vertices;  // scattering vertices so far (null crossings do not count)
    // Until the first vertex that is not a crossing (or, with start.throughSpecular, not a
    // purely specular bounce): the stretch crossed with exact transmittance only.
    bool firstSegment = true;
    const int maxDepth = settings_.maxDepth;
    const auto mayScatterAgain = [&] { return maxDepth < 0 || vertices < maxDepth; };
    // Restriction to medium-medium prefixes: contributions count from the second vertex on.
    const bool restricted = settings_.onlyMediumToMedium;
    const auto counts = [&] { return !restricted || vertices >= 2; };
    // An emitter hit at the end of the current segment is counted: with weight 1 where NEE could
    // not have found it (the camera ray itself, or the bounce before was a Dirac lobe); after a
    // non-Dirac BSDF sample at a surface vertex (bsdfPdf > 0), with the power heuristic against
    // NEE from that vertex (bsdfFrom), which counted the same path with the complementary weight.
    bool emissionCounts = start.emissionOnFirstHit && !restricted;
    float bsdfPdf = 0.0f;
    Vec3 bsdfFrom(0.0f);
    // The BSDF ray's transmittance so far, and whether it crosses without sampling collisions.
    Rgb bsdfTransmittance(1.0f);
    bool bsdfPassesSurely = false;

    // After x1 (see PathStart::afterFirstSurface): the segment to x2 is crossed with
    // exact transmittance (NotInMedium) or must scatter (InMedium); until x2.
    using After = PathStart::AfterFirstSurface;
    After afterX1 = After::Any;
    bool pastX1 = false;
    // start.surfaceVplRadius: x1's position while the path heads for x2 from x1's non-Dirac lobe.
    std::optional<Vec3> x1ForVpls;

    float segmentStart = ray.tMin;  // where the ray entered its current medium
    int mediumBeforeCrossing = medium;  // before the last null boundary crossed
    for (int steps = 0; steps < 100000; ++steps) {
        const auto hit = scene_.intersect(ray);
        const float tSurface = hit ? hit->t : ray.tMax;

        if (medium >= 0 && ((firstSegment && start.firstSegmentTransmittanceOnly) || afterX1 == After::NotInMedium)) {
            throughput *= scene_.media()[medium].transmittance(tSurface - segmentStart);
        } else if (medium >= 0) {
            const HomogeneousMedium& m = scene_.media()[medium];
            // uDistance first: the order of the draws fixed in the source, not by the compiler.
            const float uDistance = rng.next(), uChannel = rng.next();
            const FreeFlightSample flight = m.sampleFreeFlight(tSurface - segmentStart, uChannel, uDistance);
            throughput *= flight.weight;
            if (bsdfPdf > 0.0f && !flight.scattered) bsdfTransmittance *= m.transmittance(tSurface - segmentStart);
            if (flight.scattered) {
                afterX1 = After::Any;  // x2 is this medium vertex
                pastX1 = true;         // (or the first segment ended in the medium: no x1)
                ++vertices;
                firstSegment = false;
                emissionCounts = false;
                if (!mayScatterAgain()) break;
                const Vec3 x = ray.at(segmentStart + flight.t);
                const DirectLighting direct = sampleDirectLighting(scene_, x, nullptr, medium, rng);
                if (counts() && !isBlack(direct.radianceOverPdf)) {
                    const float phase = m.phase().eval(ray.direction, direct.direction);
                    // An area light is also found by the phase sample below (MIS, as at surfaces):
                    // NEE alone carries 1 / d^2 next to an emitting wall, of unbounded variance.
                    const float weight = settings_.lightMis && direct.pdf > 0.0f
                                             ? powerHeuristic(direct.pdf, phase * passProbability(direct.transmittance, false))
                                             : 1.0f;
                    result += throughput * direct.radianceOverPdf * (phase * weight);
                }
                // Exact phase sampling: the weight f/pdf is 1.
                const PhaseSample next = m.phase().sample(ray.direction, Vec2(rng.next(), rng.next()));
                ray = Ray{x, next.direction};
                segmentStart = 0.0f;
                // An emitter this ray reaches unscattered counts where NEE from x did (counts()),
                // with the complementary weight.
                emissionCounts = settings_.lightMis && counts();
                bsdfPdf = emissionCounts ? next.pdf : 0.0f;
                bsdfFrom = x;
                bsdfPassesSurely = false;
                bsdfTransmittance = Rgb(1.0f);
                if (vertices >= settings_.rouletteDepth) {
                    const float q = std::min(maxComponent(throughput), 0.95f);
                    if (rng.next() >= q) break;
                    throughput /= q;
                }
                continue;
            }
        }
        if (!hit || isBlack(throughput)) break;

        const SceneShape& shape = scene_.shapes()[hit->shape];
        if (emissionCounts && shape.emitter >= 0) {
            const Emitter& emitter = *scene_.emitters()[shape.emitter];
            float weight = 1.0f;
            if (bsdfPdf > 0.0f) {
                const float lightPdf = scene_.emitterSampler().probability(size_t(shape.emitter)) *
                                       emitter.pdfDirect(bsdfFrom, hit->position, hit->geometricNormal);
                weight = powerHeuristic(bsdfPdf * passProbability(bsdfTransmittance, bsdfPassesSurely), lightPdf);
            }
            result += throughput * emitter.emittedRadiance(hit->geometricNormal, -ray.direction) * weight;
        }

        const Bsdf& bsdf = shape.bsdf;
        if (bsdf.isNull()) {
            if (!Scene::withinCrossing(ray, *hit)) mediumBeforeCrossing = medium;
            medium = scene_.mediumAfter(*hit, ray.direction, medium);
            segmentStart = hit->t;
            Scene::continuePast(ray, *hit);  // same ray: distances stay exact
            continue;
        }
        if (afterX1 == After::InMedium) break;  // x2 is a surface: not a path of this restriction
        afterX1 = After::Any;
        const bool specularChain =
            firstSegment && start.throughSpecular && bsdf.isPurelySpecular() && vertices < kMaxSpecularChain;
        const bool atX1 = !specularChain && !pastX1;
        if (!specularChain) firstSegment = false, pastX1 = true;
        const bool onlyInMediumNext = atX1 && start.afterFirstSurface == After::InMedium;
        bool onlyDiracNext = atX1 && start.diracAtFirstSurfaceOnly;
        // x2 of part (a) with surface VPLs: its non-Dirac reflection weighs 1 - (d/R)^2 (PathStart).
        float nonDiracWeight = 1.0f;
        if (x1ForVpls && !specularChain) {  // x2 (specularChain is false past x1)
            if (reflectsBroadly(bsdf)) {
                const float d2 = (hit->position - *x1ForVpls).length2();
                const float r2 = start.surfaceVplRadius * start.surfaceVplRadius;
                nonDiracWeight = d2 < r2 ? 1.0f - d2 / r2 : 0.0f;
                if (!(nonDiracWeight > 0.0f)) onlyDiracNext = true;
            }
            x1ForVpls.reset();
        }
        if (Scene::withinCrossing(ray, *hit)) medium = mediumBeforeCrossing;
        if (restricted && vertices + 1 <= 2) break;  // a surface among the first two vertices

        ++vertices;
        if (!mayScatterAgain()) break;
        const ShadingPoint sp = hit->shadingPoint();
        const Vec3 wo = -ray.direction;
        if (!bsdf.isPurelySpecular() && !onlyInMediumNext && !onlyDiracNext) {
            const DirectLighting direct = sampleDirectLighting(scene_, hit->position, &*hit, medium, rng);
            if (counts() && !isBlack(direct.radianceOverPdf)) {
                const Rgb f = bsdf.eval(sp, wo, direct.direction, TransportMode::Radiance);
                // An area light (pdf > 0) is also found by the BSDF sample below, which counts
                // under the same condition (counts(), no medium collision on the way).
                const bool passesSurely = atX1 && start.afterFirstSurface == After::NotInMedium;
                const float weight =
                    settings_.lightMis && direct.pdf > 0.0f
                        ? powerHeuristic(direct.pdf, bsdf.pdf(sp, wo, direct.direction) *
                                                         passProbability(direct.transmittance, passesSurely))
                        : 1.0f;
                if (!isBlack(f)) result += throughput * direct.radianceOverPdf * f * (weight * nonDiracWeight);
            }
        }
        const auto sampled = bsdf.sample(sp, wo, Vec2(rng.next(), rng.next()), rng.next(), TransportMode::Radiance);
        if (!sampled || isBlack(sampled->weight)) break;
        if (atX1 && !sampled->delta) afterX1 = start.afterFirstSurface;
        if (onlyInMediumNext && sampled->delta) break;
        if (onlyDiracNext && !sampled->delta) break;
        throughput *= sampled->weight;
        if (!sampled->delta) throughput *= nonDiracWeight;
        if (atX1 && !sampled->delta && start.surfaceVplRadius > 0.0f && afterX1 == After::NotInMedium &&
            lambertianBounded(bsdf))
            x1ForVpls = hit->position;
        const bool misEmission = settings_.lightMis && !sampled->delta;
        emissionCounts = (sampled->delta || misEmission) && (!restricted || vertices >= 2) && afterX1 != After::InMedium;
        bsdfPdf = misEmission ? sampled->pdf : 0.0f;
        bsdfFrom = hit->position;
        // Part (a)'s x1 crosses the next segment by transmittance only: its BSDF ray always passes.
        bsdfPassesSurely = afterX1 == After::NotInMedium;
        bsdfTransmittance = Rgb(1.0f);
        medium = scene_.mediumAfter(*hit, sampled->wi, medium);
        ray = Ray{Scene::offsetOrigin(*hit, sampled->wi), sampled->wi};
        segmentStart = 0.0f;
        if (vertices >= settings_.rouletteDepth) {
            const float q = std::min(maxComponent(throughput), 0.95f);
            if (rng.next() >= q) break;
            throughput /= q;
        }
    }
    return result;
}

}  // namespace vrl
