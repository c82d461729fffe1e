// Transform: an affine map of 3D space (e.g. worldFromObject, worldFromCamera).
// Composition follows Mitsuba's XML: each element of a <transform> is applied
// after the previous one, i.e. `a.then(b)` maps p to b(a(p)).
#pragma once

#include "render/core/geometry.h"

#include <Imath/ImathMatrix.h>

#include <array>

namespace vrl {

class Transform {
public:
    Transform() = default;  // identity

    static Transform translate(const Vec3& offset);
    static Transform scale(const Vec3& factors);
    // Rotation by `degrees` about `axis` (right-handed, Mitsuba's convention).
    static Transform rotate(const Vec3& axis, float degrees);
    // A matrix given row-major for column vectors (p' = M p), as Mitsuba's <matrix>.
    static Transform fromRowMajor(const std::array<double, 16>& rowMajor);
    // Camera-to-world frame at `origin` looking at `target` (Mitsuba's lookat:
    // +z towards the target, +x = up x dir ("left"), +y = the orthogonalised up).
    // Throws std::invalid_argument when origin == target or up is parallel to the view.
    static Transform lookAt(const Vec3& origin, const Vec3& target, const Vec3& up);

    Transform then(const Transform& next) const;  // next(this(p))
    Transform inverse() const;

    Vec3 applyPoint(const Vec3& p) const;
    Vec3 applyVector(const Vec3& v) const;
    // Normals transform by the inverse transpose; the result is not normalised.
    Vec3 applyNormal(const Vec3& n) const;
    // True if the transform flips orientation (negative determinant).
    bool flipsHandedness() const;
    bool isIdentity() const { return m_ == Imath::M44d(); }

    // Row-major entries for column vectors (inverse of fromRowMajor).
    std::array<double, 16> toRowMajor() const;

private:
    explicit Transform(const Imath::M44d& rowVectorMatrix) : m_(rowVectorMatrix) {}
    Imath::M44d m_;  // Imath convention: p' = p * m_
};

}  // namespace vrl
