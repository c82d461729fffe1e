// PixelFootprint: where a film square (a pixel, or a quarter of one that an
// interleaved point of part (c) stands for: interleaved_points.h) lands on the
// textures of the surface its shading point lies on.
//
// Why: part (c) (VRL-lit surfaces) is evaluated once per pixel, at one camera ray
// jittered inside the pixel (or at 2 x 2 interleaved points, one per quarter:
// interleaved_points.h), while the path-sampled parts average the pixel's spp
// rays. On a textured surface the one point's texel then decides the pixel's value
// and moves with the jitter, a large share of (c)'s noise between seeds on
// textured scenes such as staircase (crops with the textures made constant lose it).
// So the shading point's texture lookups are averaged over the pixel instead
// (PreparedBsdf::averageTexturesOver), as pbrt filters textures over a ray's
// footprint: the point keeps its geometry (position, normals, wo), its BSDF takes
// the mean lookup of kFootprintSide^2 points of the film square.
//
// The points: the midpoints of a kFootprintSide x kFootprintSide grid over the film
// square; each one's camera ray meets the plane of the hit triangle, and the
// triangle's uv map (extended linearly over its plane, Scene::texcoordOnPlane)
// gives its texture coordinates. Deterministic: no random numbers are drawn.
// What it approximates: the pixel's mean of E(x) rho(x) by E(x0) times the mean of
// rho, exact where the light arriving (E) is the same over the pixel; the
// difference is their covariance inside one pixel. Only for a point the camera sees
// directly (no specular bounce before it, so the film square maps to its plane by
// the camera's rays); elsewhere the point keeps its own lookups.
#pragma once

#include "render/core/geometry.h"
#include "render/scene/scene.h"

#include <array>
#include <optional>

namespace vrl {

// A square of the film, in film pixel coordinates (after the crop offset, as
// PerspectiveCamera::generateRay takes them): [x, x + size] x [y, y + size].
struct FilmSquare {
    float x = 0.0f, y = 0.0f, size = 1.0f;
};

inline constexpr int kFootprintSide = 4;
inline constexpr int kFootprintPoints = kFootprintSide * kFootprintSide;

// The texture coordinates of the grid's points on the plane of `hit` (seen from
// the camera), row by row from (x, y). Empty where a point's ray misses that plane
// (parallel to it, or the plane behind the camera): the caller keeps the point's
// own lookups.
std::optional<std::array<Vec2, kFootprintPoints>> footprintTexcoords(const Scene& scene, const FilmSquare& square,
                                                                     const SurfaceHit& hit);

}  // namespace vrl
