// Converts a ShapeDescription into a world-space TriangleMesh: loads OBJ files
// (tinyobjloader; quads and polygons triangulated, v, v/vt, v//vn, v/vt/vn corners may be
// mixed) and Mitsuba .serialized files (serialized_mesh.h, shape `shapeIndex`), and
// tessellates Mitsuba's analytic shapes (rectangle: [-1,1]^2 in z=0 facing +z; cube:
// [-1,1]^3 facing out; disk: unit disk facing +z; sphere: centre/radius, facing out).
// Applies toWorld (positions as points, normals with the inverse transpose) and
// flipNormals; faceNormals drops a mesh file's vertex normals.
// Texture coordinates, as Mitsuba defines them:
//   rectangle  (-1,-1) -> (0,0), (1,-1) -> (1,0), (1,1) -> (1,1), (-1,1) -> (0,1)
//   cube       every face onto [0,1]^2, corners as in Mitsuba 0.5's cube.cpp
//   sphere     (phi / 2 pi, theta / pi), theta from the object-space +z axis; the seam
//              phi = 2 pi has its own vertices with u = 1
//   disk       (r, phi / 2 pi); each wedge's centre vertex takes the wedge's middle angle
//   obj        the file's vt; when some corners have vt and others not, the others get
//              (0, 0) (a file without any vt has no texcoords)
//   serialized the file's texcoords, when it has them
// Throws SceneError naming the shape for missing, unreadable, corrupt or empty meshes.
#pragma once

#include "render/core/triangle_mesh.h"
#include "render/description/scene_description.h"

namespace vrl {

// Tessellation density for curved shapes (sphere: 2N x N quads; disk: 2N wedges).
inline constexpr int kCurvedShapeSegments = 48;

TriangleMesh buildShapeMesh(const ShapeDescription& shape);

}  // namespace vrl
