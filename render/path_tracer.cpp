#include "render/path_tracer.h"

#include "render/sampling.h"

#include <algorithm>
#include <cmath>

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
    return {light.direction, light.weight * tr / probability};
}

namespace {

}  // namespace

Rgb VolumetricPathTracer::radiance(Ray ray, int medium, Rng& rng, const PathStart& start) const {
    Rgb result(0.0f), throughput(1.0f);
    int vertices = start.vertices;  // scattering vertices so far (null crossings do not count)
    bool firstSegment = true;  // until the first scattering vertex
    const int maxDepth = settings_.maxDepth;
    const auto mayScatterAgain = [&] { return maxDepth < 0 || vertices < maxDepth; };
    // Restriction to medium-medium prefixes: contributions count from the second vertex on.
    const bool restricted = settings_.onlyMediumToMedium;
    const auto counts = [&] { return !restricted || vertices >= 2; };

    float segmentStart = ray.tMin;  // where the ray entered its current medium
    int mediumBeforeCrossing = medium;  // before the last null boundary crossed
    for (int steps = 0; steps < 100000; ++steps) {
        const auto hit = scene_.intersect(ray);
        const float tSurface = hit ? hit->t : ray.tMax;

        if (medium >= 0 && firstSegment && start.firstSegmentTransmittanceOnly) {
            throughput *= scene_.media()[medium].transmittance(tSurface - segmentStart);
        } else if (medium >= 0) {
            const HomogeneousMedium& m = scene_.media()[medium];
            const FreeFlightSample flight = m.sampleFreeFlight(tSurface - segmentStart, rng.next(), rng.next());
            throughput *= flight.weight;
            if (flight.scattered) {
                ++vertices;
                firstSegment = false;
                if (!mayScatterAgain()) break;
                const Vec3 x = ray.at(segmentStart + flight.t);
                const DirectLighting direct = sampleDirectLighting(scene_, x, nullptr, medium, rng);
                if (counts() && !isBlack(direct.radianceOverPdf))
                    result += throughput * direct.radianceOverPdf * m.phase().eval(ray.direction, direct.direction);
                // Exact phase sampling: the weight f/pdf is 1.
                const PhaseSample next = m.phase().sample(ray.direction, Vec2(rng.next(), rng.next()));
                ray = Ray{x, next.direction};
                segmentStart = 0.0f;
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
        // Emission: only for paths NEE has not already accounted for.
        if (start.emissionOnFirstHit && vertices == start.vertices && !restricted && shape.emitter >= 0)
            result += throughput * scene_.emitters()[shape.emitter]->emittedRadiance(hit->geometricNormal, -ray.direction);

        if (shape.bsdf.isNull()) {
            if (!Scene::withinCrossing(ray, *hit)) mediumBeforeCrossing = medium;
            medium = scene_.mediumAfter(*hit, ray.direction, medium);
            segmentStart = hit->t;
            Scene::continuePast(ray, *hit);  // same ray: distances stay exact
            continue;
        }
        firstSegment = false;
        if (Scene::withinCrossing(ray, *hit)) medium = mediumBeforeCrossing;
        if (restricted && vertices + 1 <= 2) break;  // a surface among the first two vertices

        // Diffuse reflection on the side the ray arrived from.
        Vec3 n = hit->shadingNormal;
        const bool front = ray.direction.dot(hit->geometricNormal) < 0.0f;
        if (!front) {
            if (!shape.bsdf.twoSided) break;  // one-sided diffuse is black from behind
            n = -n;
        }
        ++vertices;
        if (!mayScatterAgain()) break;
        const Rgb albedo = shape.bsdf.reflectance;
        const DirectLighting direct = sampleDirectLighting(scene_, hit->position, &*hit, medium, rng);
        const float ng = direct.direction.dot(hit->geometricNormal) * (front ? 1.0f : -1.0f);
        if (counts() && !isBlack(direct.radianceOverPdf) && ng > 0.0f)
            result += throughput * direct.radianceOverPdf * albedo * (std::max(0.0f, direct.direction.dot(n)) * kInvPi);

        const Vec3 dir = Frame::fromNormal(n).toWorld(cosineHemisphere(Vec2(rng.next(), rng.next()))).normalized();
        if (dir.dot(hit->geometricNormal) * (front ? 1.0f : -1.0f) <= 0.0f) break;  // below the true surface
        throughput *= albedo;
        medium = scene_.mediumAfter(*hit, dir, medium);
        ray = Ray{Scene::offsetOrigin(*hit, dir), dir};
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
