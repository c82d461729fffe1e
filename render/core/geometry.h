// render/core/: math and base types every other part of the renderer builds on (geometry,
// RGB, transforms, random streams, sampling, distances, timing, triangle meshes).
// It includes nothing outside itself.
//
// Basic geometric types: points and vectors (Imath), rays, and an orthonormal
// frame around a direction. World units are the scene's units; angles radians.
#pragma once

#include <Imath/ImathVec.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace vrl {

using Vec3 = Imath::V3f;
using Vec2 = Imath::V2f;

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 1.0f / kPi;
inline constexpr float kInv4Pi = 1.0f / (4.0f * kPi);
inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

// A ray origin + t * direction for t in (tMin, tMax); direction is unit length.
// tMin > 0 continues a ray past a surface it crossed without moving its origin,
// so distances measured along it stay exact.
struct Ray {
    Vec3 origin;
    Vec3 direction;
    float tMax = kInfinity;
    float tMin = 0.0f;
    // Hits closer than `skipUntil` on the triangles (shape, triangle) in
    // skip[0, skipCount) are ignored: the surfaces the ray just crossed (several when
    // boundaries coincide or the crossing is on a shared edge). Any other surface at
    // the same distance, including another part of the same shape, is still found.
    static constexpr int kMaxSkipped = 6;
    struct Crossed {
        uint32_t shape, triangle;
    };
    Crossed skip[kMaxSkipped] = {};
    int skipCount = 0;
    float skipUntil = 0.0f;

    Vec3 at(float t) const { return origin + direction * t; }
};

// Right-handed orthonormal basis whose z axis is `normal` (Duff et al. 2017).
struct Frame {
    Vec3 s, t, n;

    static Frame fromNormal(const Vec3& normal) {
        const float sign = std::copysign(1.0f, normal.z);
        const float a = -1.0f / (sign + normal.z);
        const float b = normal.x * normal.y * a;
        return {Vec3(1.0f + sign * normal.x * normal.x * a, sign * b, -sign * normal.x),
                Vec3(b, sign + normal.y * normal.y * a, -normal.y), normal};
    }
    Vec3 toWorld(const Vec3& local) const { return s * local.x + t * local.y + n * local.z; }
    Vec3 toLocal(const Vec3& world) const { return {s.dot(world), t.dot(world), n.dot(world)}; }
};

// Scale of a position's float rounding noise (1 + its largest coordinate): offsets
// that step past a surface are multiples of it.
inline float positionScale(const Vec3& p) {
    return 1.0f + std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
}

// Unit vector from spherical coordinates around +z.
inline Vec3 sphericalDirection(float sinTheta, float cosTheta, float phi) {
    return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}

}  // namespace vrl
