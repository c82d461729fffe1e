#include "render/core/transform.h"

#include <cmath>
#include <stdexcept>

namespace vrl {

Transform Transform::translate(const Vec3& offset) {
    Imath::M44d m;
    m.setTranslation(Imath::V3d(offset.x, offset.y, offset.z));
    return Transform(m);
}

Transform Transform::scale(const Vec3& factors) {
    Imath::M44d m;
    m.setScale(Imath::V3d(factors.x, factors.y, factors.z));
    return Transform(m);
}

Transform Transform::rotate(const Vec3& axis, float degrees) {
    const Imath::V3d a = Imath::V3d(axis.x, axis.y, axis.z).normalized();
    // Rodrigues' matrix for column vectors, then transposed into Imath's row convention.
    const double angle = degrees * M_PI / 180.0, c = std::cos(angle), s = std::sin(angle), t = 1 - c;
    const std::array<double, 16> r = {
        t * a.x * a.x + c,       t * a.x * a.y - s * a.z, t * a.x * a.z + s * a.y, 0,
        t * a.x * a.y + s * a.z, t * a.y * a.y + c,       t * a.y * a.z - s * a.x, 0,
        t * a.x * a.z - s * a.y, t * a.y * a.z + s * a.x, t * a.z * a.z + c,       0,
        0,                       0,                       0,                       1};
    return fromRowMajor(r);
}

Transform Transform::fromRowMajor(const std::array<double, 16>& rowMajor) {
    Imath::M44d m;
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) m[col][row] = rowMajor[row * 4 + col];  // transpose
    return Transform(m);
}

std::array<double, 16> Transform::toRowMajor() const {
    std::array<double, 16> out{};
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) out[row * 4 + col] = m_[col][row];
    return out;
}

Transform Transform::lookAt(const Vec3& origin, const Vec3& target, const Vec3& up) {
    const Imath::V3d o(origin.x, origin.y, origin.z), t(target.x, target.y, target.z), u(up.x, up.y, up.z);
    const Imath::V3d toTarget = t - o;
    if (toTarget.length() == 0.0) throw std::invalid_argument("lookat: origin and target coincide");
    const Imath::V3d dir = toTarget.normalized();
    Imath::V3d left = u.normalized().cross(dir);
    if (left.length() < 1e-9) throw std::invalid_argument("lookat: 'up' is parallel to the viewing direction");
    left.normalize();
    const Imath::V3d newUp = dir.cross(left);
    const std::array<double, 16> m = {left.x, newUp.x, dir.x, o.x,  //
                                      left.y, newUp.y, dir.y, o.y,  //
                                      left.z, newUp.z, dir.z, o.z,  //
                                      0,      0,       0,     1};
    return fromRowMajor(m);
}

Transform Transform::then(const Transform& next) const { return Transform(m_ * next.m_); }

Transform Transform::inverse() const { return Transform(m_.inverse()); }

Vec3 Transform::applyPoint(const Vec3& p) const {
    Imath::V3d out;
    m_.multVecMatrix(Imath::V3d(p.x, p.y, p.z), out);
    return {float(out.x), float(out.y), float(out.z)};
}

Vec3 Transform::applyVector(const Vec3& v) const {
    Imath::V3d out;
    m_.multDirMatrix(Imath::V3d(v.x, v.y, v.z), out);
    return {float(out.x), float(out.y), float(out.z)};
}

Vec3 Transform::applyNormal(const Vec3& n) const {
    Imath::V3d out;
    m_.inverse().transposed().multDirMatrix(Imath::V3d(n.x, n.y, n.z), out);
    return {float(out.x), float(out.y), float(out.z)};
}

bool Transform::flipsHandedness() const {
    const Imath::M33d linear(m_[0][0], m_[0][1], m_[0][2], m_[1][0], m_[1][1], m_[1][2], m_[2][0], m_[2][1],
                             m_[2][2]);
    return linear.determinant() < 0.0;
}

}  // namespace vrl
