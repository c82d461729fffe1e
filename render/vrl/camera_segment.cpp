#include "render/vrl/camera_segment.h"

#include "render/core/rng.h"
#include "render/scene/scene.h"

namespace vrl {

std::vector<CameraSegment> cameraSegments(const Scene& scene, const Ray& cameraRay, int medium, Rng* rng,
                                          int maxDepth) {
    return cameraPath(scene, cameraRay, medium, rng, maxDepth).segments;
}

CameraPathSurface cameraPathSurface(const Scene& scene, const SurfaceHit& hit, const Vec3& wo, int medium,
                                    const Rgb& throughput, int specularBefore) {
    return CameraPathSurface{hit, wo, medium, throughput, specularBefore,
                             scene.shapes()[hit.shape].bsdf.prepare(hit.shadingPoint(), wo)};
}

CameraPath cameraPath(const Scene& scene, const Ray& cameraRay, int medium, Rng* rng, int maxDepth) {
    CameraPath path;
    std::vector<CameraSegment>& segments = path.segments;
    int mediumBeforeCrossing = medium;  // before the last null boundary crossed
    Ray ray = cameraRay;
    Rgb throughput(1.0f);
    int specular = 0;
    float segmentStart = ray.tMin;
    for (int crossings = 0; crossings < 256; ++crossings) {
        const auto hit = scene.intersect(ray);
        const float end = hit ? hit->t : ray.tMax;
        if (medium >= 0 && end > segmentStart) {
            const float length = std::isfinite(end) ? end - segmentStart : 1e30f;
            segments.push_back({ray.at(segmentStart), ray.direction, length, medium, throughput, specular});
            throughput *= scene.media()[medium].transmittance(end - segmentStart);
        }
        if (!hit) break;
        const Bsdf& bsdf = scene.shapes()[hit->shape].bsdf;
        if (bsdf.isNull()) {
            if (!Scene::withinCrossing(ray, *hit)) mediumBeforeCrossing = medium;
            medium = scene.mediumAfter(*hit, ray.direction, medium);
            segmentStart = hit->t;
            Scene::continuePast(ray, *hit);
            continue;
        }
        // A specular bounce is a path vertex: after it, a medium vertex on the next
        // segment and a light still need to fit (specular + 1 + 2 segments).
        if (!bsdf.isPurelySpecular()) {
            // A surface flush with the boundary just crossed is met from the medium before it.
            const int arrival = Scene::withinCrossing(ray, *hit) ? mediumBeforeCrossing : medium;
            path.surface = cameraPathSurface(scene, *hit, -ray.direction, arrival, throughput, specular);
            break;
        }
        if (!rng || specular >= kMaxSpecularChain) break;
        if (maxDepth >= 0 && specular + 3 > maxDepth) break;
        const auto sampled = bsdf.sample(hit->shadingPoint(), -ray.direction, Vec2(rng->next(), rng->next()),
                                         rng->next(), TransportMode::Radiance);
        if (!sampled || isBlack(sampled->weight)) break;
        throughput *= sampled->weight;
        ++specular;
        medium = scene.mediumAfter(*hit, sampled->wi, medium);
        ray = Ray{Scene::offsetOrigin(*hit, sampled->wi), sampled->wi};
        segmentStart = 0.0f;
    }
    return path;
}

}  // namespace vrl
