#include "render/integrators/pixel_footprint.h"

#include <cmath>

namespace vrl {

std::optional<std::array<Vec2, kFootprintPoints>> footprintTexcoords(const Scene& scene, const FilmSquare& square,
                                                                     const SurfaceHit& hit) {
    const Imath::V3d n(hit.geometricNormal), x0(hit.position);
    std::array<Vec2, kFootprintPoints> uvs;
    const float step = square.size / float(kFootprintSide);
    for (int j = 0; j < kFootprintSide; ++j) {
        for (int i = 0; i < kFootprintSide; ++i) {
            const Ray ray = scene.camera().generateRay(square.x + (float(i) + 0.5f) * step,
                                                       square.y + (float(j) + 0.5f) * step);
            // Where o + t d meets the plane n . (p - x0) = 0.
            const Imath::V3d o(ray.origin), d(ray.direction);
            const double t = n.dot(x0 - o) / n.dot(d);
            if (!(t > 0.0) || !std::isfinite(t)) return std::nullopt;
            const Imath::V3d p = o + d * t;
            uvs[size_t(j * kFootprintSide + i)] = scene.texcoordOnPlane(hit, Vec3(float(p.x), float(p.y), float(p.z)));
        }
    }
    return uvs;
}

}  // namespace vrl
