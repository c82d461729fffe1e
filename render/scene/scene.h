// render/scene/: the scene: its plain description (scene_description.h), the
// camera, SceneError, and the immutable render Scene with its Embree BVH and
// medium navigation.
//
// Scene: the immutable render scene built from a SceneDescription. Owns the
// world-space meshes, their materials and media links, the media, emitters,
// camera and the Embree device + BVH (closest-hit and occlusion queries). It is
// safe to query from many threads at once.
#pragma once

#include "render/core/triangle_mesh.h"
#include "render/lights/emitter.h"
#include "render/materials/bsdf.h"
#include "render/materials/texture.h"
#include "render/media/homogeneous_medium.h"
#include "render/scene/camera.h"
#include "render/description/scene_description.h"

#include <memory>
#include <optional>
#include <vector>

namespace vrl {

struct SceneShape {
    TriangleMesh mesh;
    Bsdf bsdf;
    int emitter = -1;         // index into Scene::emitters(), area lights
    int interiorMedium = -1;  // -1: vacuum
    int exteriorMedium = -1;
    bool changesMedium = false;  // declares interior or exterior (else crossing keeps the medium)
};

struct SurfaceHit {
    float t = 0.0f;
    Vec3 position;
    Vec3 geometricNormal;  // unit, the mesh's front (outside / emitting) side
    Vec3 shadingNormal;    // unit, interpolated, on the same side as geometricNormal
    Vec2 uv{0.0f, 0.0f};   // texture coordinates (barycentrics for meshes without uvs)
    uint32_t shape = 0;
    uint32_t triangle = 0;
    float scale = 1.0f;  // largest |coordinate| of the hit triangle's vertices (offsets scale with it)

    ShadingPoint shadingPoint() const { return {geometricNormal, shadingNormal, uv}; }
};

class Scene {
public:
    // Loads meshes and builds the BVH. Media with equal coefficients and phase are
    // merged into one (description() and media() hold the merged list). Throws
    // SceneError for problems in the description (missing meshes, invalid media) and
    // std::runtime_error for Embree failures.
    static std::unique_ptr<Scene> build(const SceneDescription& description);
    ~Scene();
    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;

    const SceneDescription& description() const { return description_; }
    const PerspectiveCamera& camera() const { return camera_; }
    int cameraMedium() const { return description_.sensor.medium; }
    const std::vector<SceneShape>& shapes() const { return shapes_; }
    const std::vector<HomogeneousMedium>& media() const { return media_; }
    const HomogeneousMedium* medium(int index) const { return index >= 0 ? &media_[index] : nullptr; }
    const std::vector<std::unique_ptr<Emitter>>& emitters() const { return emitters_; }
    const EmitterSampler& emitterSampler() const { return *emitterSampler_; }
    bool hasSurfaces() const { return !shapes_.empty(); }
    // False when segments between two points of the medium can never be blocked:
    // its boundary is convex and nothing else lies inside it (no occlusion rays needed).
    bool mediumNeedsVisibility(int medium) const { return medium < 0 || mediumNeedsVisibility_[medium]; }
    bool hasNullSurfaces() const { return hasNullSurfaces_; }
    // Some surface has a purely specular BSDF (glass, mirror): camera paths continue through it.
    bool hasSpecularSurfaces() const { return hasSpecularSurfaces_; }
    // The loaded textures, in SceneDescription::textures order.
    const std::vector<std::shared_ptr<const Texture>>& textures() const { return textures_; }

    // Closest surface along the ray within (0, ray.tMax).
    std::optional<SurfaceHit> intersect(const Ray& ray) const;
    // The texture coordinates the hit triangle's linear uv map gives `point`, taken on
    // the triangle's plane (its projection there; outside the triangle the map is
    // extended linearly). hit.uv where the triangle is degenerate.
    Vec2 texcoordOnPlane(const SurfaceHit& hit, const Vec3& point) const;
    // True if any surface blocks the segment (origin, origin + t direction), t < tMax.
    bool occluded(const Ray& ray) const;
    // No surface between two points (stopping 1e-4 of the distance short of `to`, so
    // that an area light's own surface does not occlude); null surfaces occlude here.
    bool visible(const Vec3& from, const Vec3& to) const;
    // Transmittance from `from` (in medium `medium`) to `to`, passing through null
    // boundaries (switching media) and returning zero at any other surface.
    Rgb transmittance(const Vec3& from, const Vec3& to, int medium) const;
    // The medium at `point`, found by walking from the camera through the declared
    // media boundaries (the camera's medium if none is crossed).
    int mediumAt(const Vec3& point) const;
    // The medium on the side of `shape` that `direction` points into from `hit`.
    int mediumAfter(const SurfaceHit& hit, const Vec3& direction, int currentMedium) const;

    // Origin for a ray leaving a surface point in `direction` (offset against self-hits).
    static Vec3 offsetOrigin(const SurfaceHit& hit, const Vec3& direction);
    // Continues `ray` past the surface it hit at `hit` (crossing a null boundary):
    // the same ray from the hit distance on, ignoring only that shape there.
    static void continuePast(Ray& ray, const SurfaceHit& hit);
    // True if `hit` lies within the crossing window of the null boundary `ray` just
    // crossed: a surface flush with that boundary (a medium box resting on a floor).
    // Such a surface is met from the side the ray came from: use the medium from
    // before the crossing.
    static bool withinCrossing(const Ray& ray, const SurfaceHit& hit) {
        return ray.skipCount > 0 && hit.t < ray.skipUntil;
    }

private:
    Scene(const SceneDescription& description);
    void buildBvh();
    void classifyMediumBoundaries();

    SceneDescription description_;
    PerspectiveCamera camera_;
    std::vector<SceneShape> shapes_;
    std::vector<HomogeneousMedium> media_;
    std::vector<std::unique_ptr<Emitter>> emitters_;
    std::unique_ptr<EmitterSampler> emitterSampler_;
    bool hasNullSurfaces_ = false;
    bool hasSpecularSurfaces_ = false;
    std::vector<std::shared_ptr<const Texture>> textures_;
    std::vector<bool> mediumNeedsVisibility_;
    struct Embree;
    std::unique_ptr<Embree> embree_;
};

}  // namespace vrl
