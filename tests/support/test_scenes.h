// Small scenes built in code (no parser) for the renderer's integration tests,
// each with a known answer.
#pragma once

#include "render/scene/scene_description.h"

namespace vrl::test {

// Diffuse (Lambertian) and null surface models for scenes built in code.
inline BsdfDescription diffuseBsdf(const Rgb& reflectance, bool twoSided) {
    BsdfDescription bsdf;
    bsdf.kind = BsdfDescription::Kind::Diffuse;
    bsdf.reflectance.value = reflectance;
    bsdf.twoSided = twoSided;
    return bsdf;
}
inline BsdfDescription nullBsdf() {
    BsdfDescription bsdf;
    bsdf.kind = BsdfDescription::Kind::Null;
    return bsdf;
}

// A camera at the origin looking down +z with the given film and fov.
SensorDescription cameraAtOrigin(int width, int height, float fovDegrees);

// Closed sphere (radius 1, centred on the camera) emitting `radiance` inwards,
// black walls, filled with a non-absorbing medium of scattering `sigmaS`:
// every pixel's expected radiance is exactly `radiance`.
SceneDescription emittingSphereFurnace(const Rgb& radiance, const Rgb& sigmaS, float g);

// A camera in vacuum looking through a slab (thickness `thickness` along z,
// null boundary) of pure absorber `sigmaA` at a large area light of radiance
// `radiance` facing the camera: the centre pixels see radiance exp(-sigmaA d).
SceneDescription absorberSlab(const Rgb& radiance, const Rgb& sigmaA, float thickness);

// A point light of `intensity` at `lightPosition` in an infinite medium that
// also holds the camera (no surfaces).
SceneDescription pointLightInInfiniteMedium(const Rgb& intensity, const Vec3& lightPosition, const Rgb& sigmaS,
                                           const Rgb& sigmaA, float g);

// Medium only: a null-bounded cube [-1,1]^3 of medium (sigmaS, sigmaA, HG g)
// seen from outside (camera in vacuum at z = -3.5), lit by a point light inside it.
SceneDescription mediumOnlyCube(const Rgb& sigmaS, const Rgb& sigmaA, float g);

// Surfaces: a closed room (two-sided diffuse box [-2,2]^3) filled with a medium,
// an opaque diffuse occluder box inside, a spot light and an area light (a
// rectangle under the ceiling facing down). Flat geometry only.
SceneDescription litRoomWithOccluder(const Rgb& sigmaS, const Rgb& sigmaA, float g);

// litRoomWithOccluder with a solid glass sphere (vacuum inside, the medium
// outside) in front of the occluder and a copper mirror on the right wall:
// camera paths reach the medium through glass and in the mirror.
SceneDescription glassAndMirrorRoom(const Rgb& sigmaS, const Rgb& sigmaA, float g);

// A closed room (cube of half-size 2) with two-sided diffuse walls, a diffuse
// sphere, a spot light and a scene-filling medium: a little of everything.
SceneDescription smallSmokeRoom();

}  // namespace vrl::test
