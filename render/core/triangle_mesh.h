// TriangleMesh: world-space triangles of one scene shape. Every shape kind
// (obj, rectangle, cube, sphere, disk) becomes one of these. Winding is
// counter-clockwise seen from the front, so the geometric normal
// (p1-p0)x(p2-p0) points to the shape's outside / emitting side.
#pragma once

#include "render/core/geometry.h"

#include <array>
#include <cstdint>
#include <vector>

namespace vrl {

struct TriangleMesh {
    std::vector<Vec3> positions;                 // world space
    std::vector<Vec3> normals;                   // per vertex, unit; empty = flat shading
    std::vector<std::array<uint32_t, 3>> triangles;
    std::vector<Vec2> texcoords;  // per vertex uv; empty = none (uv = barycentrics)

    float triangleArea(size_t i) const {
        const auto& t = triangles[i];
        return 0.5f * (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]).length();
    }
    Vec3 geometricNormal(size_t i) const {
        const auto& t = triangles[i];
        return (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]).normalized();
    }
    // Interpolated vertex normal at barycentrics (u, v) (weights 1-u-v, u, v), or
    // the geometric normal for flat meshes.
    Vec3 shadingNormal(size_t i, float u, float v) const {
        if (normals.empty()) return geometricNormal(i);
        const auto& t = triangles[i];
        return (normals[t[0]] * (1 - u - v) + normals[t[1]] * u + normals[t[2]] * v).normalized();
    }
    // Interpolated uv at barycentrics (u, v); meshes without texcoords give (u, v).
    Vec2 texcoord(size_t i, float u, float v) const {
        if (texcoords.empty()) return {u, v};
        const auto& t = triangles[i];
        return texcoords[t[0]] * (1 - u - v) + texcoords[t[1]] * u + texcoords[t[2]] * v;
    }
};

}  // namespace vrl
