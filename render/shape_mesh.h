// Converts a ShapeDescription into a world-space TriangleMesh: loads OBJ files
// (tinyobjloader) and tessellates Mitsuba's analytic shapes (rectangle: [-1,1]^2
// in z=0 facing +z; cube: [-1,1]^3 facing out; disk: unit disk facing +z;
// sphere: centre/radius, facing out). Applies toWorld and flipNormals.
// Throws SceneError naming the shape for missing, unreadable or empty meshes.
#pragma once

#include "render/scene_description.h"
#include "render/triangle_mesh.h"

namespace vrl {

// Tessellation density for curved shapes (sphere: 2N x N quads; disk: 2N wedges).
inline constexpr int kCurvedShapeSegments = 48;

TriangleMesh buildShapeMesh(const ShapeDescription& shape);

}  // namespace vrl
