#include "render/scene/camera.h"

#include <algorithm>
#include <array>

#include <cmath>

namespace vrl {

PerspectiveCamera::PerspectiveCamera(const SensorDescription& sensor)
    : worldFromCamera_(sensor.toWorld),
      cameraFromWorld_(sensor.toWorld.inverse()),
      position_(sensor.toWorld.applyPoint(Vec3(0.0f))),
      viewAxis_(sensor.toWorld.applyVector(Vec3(0.0f, 0.0f, 1.0f)).normalized()),
      width_(sensor.width),
      height_(sensor.height),
      crop_(sensor.crop ? checkFilmCrop(*sensor.crop, sensor.width, sensor.height) : std::nullopt),
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

std::optional<PerspectiveCamera::Projection> PerspectiveCamera::project(const Vec3& p) const {
    const Vec3 toP = p - position_;
    const float depth = toP.dot(viewAxis_);  // world units, as generateRay's clip distances
    if (!(depth > nearClip_ && depth < farClip_)) return std::nullopt;
    // generateRay's inverse: local direction (-ndcX tanHalfX, -ndcY tanHalfY, 1); a
    // uniform scale of the sensor transform cancels in the ratios.
    const Vec3 local = cameraFromWorld_.applyVector(toP);
    const float filmX = (1.0f - local.x / (local.z * tanHalfX_)) * 0.5f * float(width_);
    const float filmY = (1.0f - local.y / (local.z * tanHalfY_)) * 0.5f * float(height_);
    const float imageX = filmX - float(cropX0()), imageY = filmY - float(cropY0());
    if (!(imageX >= 0.0f && imageX < float(width()) && imageY >= 0.0f && imageY < float(height()))) return std::nullopt;
    Projection out;
    out.x = std::min(int(imageX), width() - 1);
    out.y = std::min(int(imageY), height() - 1);
    out.offsetX = imageX - float(out.x) - 0.5f;
    out.offsetY = imageY - float(out.y) - 0.5f;
    out.distance = toP.length();
    const float cosTheta = depth / out.distance;
    out.rayOrigin = position_ + toP * (nearClip_ / depth);  // at depth nearClip, where generateRay's rays start
    const float pixelArea = (2.0f * tanHalfX_ / float(width_)) * (2.0f * tanHalfY_ / float(height_));
    out.importance = 1.0f / (pixelArea * cosTheta * cosTheta * cosTheta);
    return out;
}

Imath::M44f PerspectiveCamera::worldToCamera() const {
    const std::array<double, 16> m = worldFromCamera_.inverse().toRowMajor();  // column vectors
    Imath::M44f out;
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) out[row][col] = float(m[size_t(4 * col + row)]);  // transpose: row vectors
    for (int row = 0; row < 4; ++row) out[row][0] = -out[row][0];  // Mitsuba's +x is the image's left
    return out;
}

Imath::M44f PerspectiveCamera::worldToNDC() const {
    // Camera (x right, y up, z forward) to NDC: x/z = tanHalfX at the right edge, y/z = tanHalfY at the top.
    Imath::M44f projection(0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f,
                           0.0f);
    projection[0][0] = 0.5f / tanHalfX_;
    projection[1][1] = -0.5f / tanHalfY_;
    projection[2][0] = 0.5f;
    projection[2][1] = 0.5f;
    projection[2][2] = 1.0f;
    projection[2][3] = 1.0f;
    if (crop_) {
        // Film NDC to the crop window's: x' = (x W - x0) / w, y' likewise (the offset times w, as x and y are).
        Imath::M44f toWindow;  // identity
        toWindow[0][0] = float(width_) / float(crop_->width);
        toWindow[3][0] = -float(crop_->x0) / float(crop_->width);
        toWindow[1][1] = float(height_) / float(crop_->height);
        toWindow[3][1] = -float(crop_->y0) / float(crop_->height);
        projection = projection * toWindow;
    }
    return worldToCamera() * projection;
}

}  // namespace vrl
