// Small scenes built in code (no parser) for the renderer's integration tests,
// each with a known answer.
#pragma once

#include "render/description/scene_description.h"

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

// cameraAtOrigin and a point light far above (y = 50), nothing else: a base for
// geometry tests (the light only keeps Scene::build from warning).
SceneDescription cameraAndFarLight(int width, int height, float fovDegrees);

// Closed sphere (radius 1, centred on the camera) emitting `radiance` inwards,
// diffuse walls of `wallReflectance` (default black), filled with a non-absorbing
// medium of scattering `sigmaS`: every pixel's expected radiance is exactly
// radiance / (1 - wallReflectance).
SceneDescription emittingSphereFurnace(const Rgb& radiance, const Rgb& sigmaS, float g,
                                       const Rgb& wallReflectance = Rgb(0.0f));

// A camera in vacuum looking through a slab (thickness `thickness` along z,
// null boundary) of pure absorber `sigmaA` at a large area light of radiance
// `radiance` facing the camera: the centre pixels see radiance exp(-sigmaA d).
SceneDescription absorberSlab(const Rgb& radiance, const Rgb& sigmaA, float thickness);

// A point light of `intensity` at `lightPosition` in an infinite medium that
// also holds the camera (no surfaces).
SceneDescription pointLightInInfiniteMedium(const Rgb& intensity, const Vec3& lightPosition, const Rgb& sigmaS,
                                           const Rgb& sigmaA, float g);

// A sphere of radius 1 at the origin with `bsdf`, seen from (0, 0, -3.5), lit by a
// point light at (0, 3, 0), in a medium (sigmaS, sigmaA, HG g) that fills everything
// or, when `boxed`, the null-bounded cube [-4, 4]^3 (convex). Point queries on the
// sphere: part (c)'s bounds, cuts and importances.
SceneDescription sphereInMedium(const Rgb& sigmaS, const Rgb& sigmaA, float g, const BsdfDescription& bsdf,
                                bool boxed);

// Medium only: a null-bounded cube [-1,1]^3 of medium (sigmaS, sigmaA, HG g)
// seen from outside (camera in vacuum at z = -3.5), lit by a point light inside it.
SceneDescription mediumOnlyCube(const Rgb& sigmaS, const Rgb& sigmaA, float g);

// Surfaces: a closed room (two-sided diffuse box [-2,2]^3) filled with a medium,
// an opaque diffuse occluder box inside, a spot light and an area light (a
// rectangle under the ceiling facing down). Flat geometry only.
SceneDescription litRoomWithOccluder(const Rgb& sigmaS, const Rgb& sigmaA, float g);

// Mitsuba's roughplastic (Beckmann) with the given diffuse reflectance and alpha.
BsdfDescription roughPlastic(const Rgb& reflectance, float alpha, bool twoSided);

// litRoomWithOccluder (diffuse walls) whose reflectors other than the walls are
// glossy, one narrow and one broad for part (a)'s surface VPLs (reflectsBroadly):
// a rough-plastic occluder (Beckmann alpha 0.1) and a rough-conductor panel on
// the right wall (alpha 0.4, 1.8 x 1.8), both lit by the spot light.
SceneDescription roomWithGlossyReflectors(const Rgb& sigmaS, const Rgb& sigmaA, float g);

// litRoomWithOccluder with a solid glass sphere (vacuum inside, the medium
// outside) in front of the occluder and a copper mirror on the right wall:
// camera paths reach the medium through glass and in the mirror.
SceneDescription glassAndMirrorRoom(const Rgb& sigmaS, const Rgb& sigmaA, float g);

// litRoomWithOccluder with glossy surfaces for MIS: two-sided rough-plastic walls
// (Beckmann alpha 0.1), a smooth-plastic occluder (a Dirac coating over a diffuse
// base), a rough-conductor panel on the right wall (alpha 0.05), the area light
// enlarged to 1.6 x 1.6, and a null-bounded box of a second medium (sigmaS2, no
// absorption) below it, so paths to the light cross null boundaries.
SceneDescription glossyLitRoom(const Rgb& sigmaS, const Rgb& sigmaA, float g, const Rgb& sigmaS2);

// The scene without its point and spot lights. A point light's light that reaches
// a scattering vertex only through Dirac surfaces (its caustics through glass, off
// a smooth coating) has zero density in the path tracer: next-event estimation
// cannot cross a Dirac surface and a sampled direction never hits a point. Tests
// that compare light-side estimators (VRLs, light tracing) with the path tracer in
// rooms with Dirac surfaces light them by their area lights alone.
SceneDescription withoutPointLights(SceneDescription scene);
// The scene without its area lights (the emitters attached to shapes).
SceneDescription withoutAreaLights(SceneDescription scene);

// Vacuum: a rough-conductor floor (Beckmann `alpha`, y = 0 facing up) under a
// 1.2 x 1.2 area light facing down at height 1.5; the camera (16 x 12) sees the
// light's glossy reflection. Direct lighting on a glossy surface: the case where
// NEE alone is noisy and BSDF sampling is not.
SceneDescription glossyFloorUnderAreaLight(float alpha);

// A closed room (cube of half-size 2) with two-sided diffuse walls, a diffuse
// sphere, a spot light and a scene-filling medium: a little of everything.
SceneDescription smallSmokeRoom();

}  // namespace vrl::test
