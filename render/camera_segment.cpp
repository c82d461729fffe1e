#include "render/camera_segment.h"

#include "render/scene.h"

namespace vrl {

std::vector<CameraSegment> cameraSegments(const Scene& scene, const Ray& cameraRay, int medium,
                                          Rgb* transmittanceToEnd) {
    std::vector<CameraSegment> segments;
    Ray ray = cameraRay;
    Rgb transmittance(1.0f);
    float segmentStart = ray.tMin;
    for (int crossings = 0; crossings < 256; ++crossings) {
        const auto hit = scene.intersect(ray);
        const float end = hit ? hit->t : ray.tMax;
        if (medium >= 0 && end > segmentStart) {
            const float length = std::isfinite(end) ? end - segmentStart : 1e30f;
            segments.push_back({ray.at(segmentStart), ray.direction, length, medium, transmittance});
            transmittance *= scene.media()[medium].transmittance(end - segmentStart);
        }
        if (!hit || !scene.shapes()[hit->shape].bsdf.isNull()) break;
        medium = scene.mediumAfter(*hit, ray.direction, medium);
        segmentStart = hit->t;
        Scene::continuePast(ray, *hit);
    }
    if (transmittanceToEnd) *transmittanceToEnd = transmittance;
    return segments;
}

}  // namespace vrl
