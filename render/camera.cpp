#include "render/camera.h"

#include <cmath>

namespace vrl {

PerspectiveCamera::PerspectiveCamera(const SensorDescription& sensor)
    : worldFromCamera_(sensor.toWorld),
      position_(sensor.toWorld.applyPoint(Vec3(0.0f))),
      width_(sensor.width),
      height_(sensor.height),
      nearClip_(sensor.nearClip),
      farClip_(sensor.farClip) {
    const float w = float(width_), h = float(height_);
    const float tanHalf = std::tan(sensor.fov * kPi / 360.0f);
    using Axis = SensorDescription::FovAxis;
    Axis axis = sensor.fovAxis;
    if (axis == Axis::Smaller) axis = w <= h ? Axis::X : Axis::Y;
    if (axis == Axis::Larger) axis = w >= h ? Axis::X : Axis::Y;
    switch (axis) {
        case Axis::X: tanHalfX_ = tanHalf; break;
        case Axis::Y: tanHalfX_ = tanHalf * w / h; break;
        default: tanHalfX_ = tanHalf * w / std::sqrt(w * w + h * h); break;  // diagonal
    }
    tanHalfY_ = tanHalfX_ * h / w;
}

Ray PerspectiveCamera::generateRay(float filmX, float filmY) const {
    const float ndcX = 2.0f * filmX / float(width_) - 1.0f;
    const float ndcY = 2.0f * filmY / float(height_) - 1.0f;
    const Vec3 local(-ndcX * tanHalfX_, -ndcY * tanHalfY_, 1.0f);
    const Vec3 dir = worldFromCamera_.applyVector(local).normalized();
    const float localLength = local.length();  // z = 1: the clip distances scale by this
    Ray ray{position_ + dir * (nearClip_ * localLength), dir, (farClip_ - nearClip_) * localLength};
    return ray;
}

}  // namespace vrl
