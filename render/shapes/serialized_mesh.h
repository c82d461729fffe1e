// Reader for Mitsuba's `.serialized` triangle meshes (shape type="serialized"), as laid
// out by Mitsuba 0.5 (src/librender/trimesh.cpp, TriMesh::loadCompressed, readOffset;
// format notes in src/shapes/serialized.cpp). Everything is little endian:
//   per shape:  uint16 0x041C (format id), uint16 version (3 or 4), then one zlib stream:
//               uint32 flags (0x0001 vertex normals, 0x0002 texcoords, 0x0008 vertex
//               colours, 0x0010 face normals, 0x1000 single / 0x2000 double precision),
//               version 4 only: the shape's name, null-terminated,
//               uint64 vertex count, uint64 triangle count,
//               positions xyz, [normals xyz], [texcoords uv], [colours rgb] (float/double),
//               triangles as 3 x uint32 vertex indices.
//   file end:   the byte offset of every shape's header (uint64 in version 4, uint32 in
//               version 3), then uint32 shape count.
// As in Mitsuba, a file whose end holds no valid offset table is read as one shape at
// offset 0. Vertex colours are skipped, and the face-normals flag is ignored (Mitsuba 0.5's
// serialized plugin overrides it with its own faceNormals parameter, default false).
// Meshes with more than 2^32-1 vertices (whose indices Mitsuba's format note says would be
// 64-bit) are rejected.
// Errors are std::runtime_error "<file>: <problem>": missing or unreadable file, bad format
// id, unsupported version, shape index out of range (with the number of shapes), corrupt
// or truncated zlib data, counts that do not fit the data (checked before allocating
// against deflate's 1032:1 maximum ratio; arrays then grow only as data arrives), indices
// out of range, non-finite positions.
#pragma once

#include "render/core/triangle_mesh.h"

#include <filesystem>

namespace vrl {

// Shape `shapeIndex` (0-based) of `file`, in object space: positions, normals and
// texcoords when the file has them. The caller applies toWorld.
TriangleMesh loadSerializedMesh(const std::filesystem::path& file, int shapeIndex);

// How many shapes `file` holds (1 for a file without an offset table). Same errors as above
// for an unreadable file or bad header.
int serializedShapeCount(const std::filesystem::path& file);

}  // namespace vrl
