// PerspectiveCamera: Mitsuba's perspective sensor. Camera space looks along +z
// with +y up and +x to the image's left; film coordinates run from the top-left
// corner, (x + 0.5, y + 0.5) being the centre of pixel (x, y). Rays start at the
// near clip plane and end at the far clip plane, as in Mitsuba.
//
// The image is the film, or its crop window (SensorDescription::crop): image
// pixel (x, y) is film pixel (x + cropX0(), y + cropY0()). Rays and random
// streams are keyed by film pixels (generateRay, filmPixelIndex), so a cropped
// render equals that window of the full-film render bit for bit.
#pragma once

#include "render/core/geometry.h"
#include "render/description/scene_description.h"

#include <Imath/ImathMatrix.h>

#include <cstdint>
#include <optional>

namespace vrl {

class PerspectiveCamera {
public:
    explicit PerspectiveCamera(const SensorDescription& sensor);

    // The image: the crop window if there is one, else the film.
    int width() const { return crop_ ? crop_->width : width_; }
    int height() const { return crop_ ? crop_->height : height_; }
    // The film (the whole sensor) and the crop window in it, if any.
    int filmWidth() const { return width_; }
    int filmHeight() const { return height_; }
    const std::optional<FilmCrop>& crop() const { return crop_; }
    int cropX0() const { return crop_ ? crop_->x0 : 0; }
    int cropY0() const { return crop_ ? crop_->y0 : 0; }
    // The film pixel index of image pixel (x, y): what a pixel's random stream is keyed by.
    uint64_t filmPixelIndex(int x, int y) const {
        return uint64_t(y + cropY0()) * uint64_t(width_) + uint64_t(x + cropX0());
    }
    Vec3 position() const { return position_; }
    // Primary ray through film position (filmX, filmY) in pixels (of the film, not the crop).
    Ray generateRay(float filmX, float filmY) const;

    // Where the pinhole sees world point p, for estimators that connect light-path
    // vertices to the camera: the image pixel it lands in, the start of the camera
    // ray towards it (on the near clip plane, where generateRay's rays start) and
    // the pinhole's importance for that direction. None when p is off the image
    // (or its crop window) or outside the clip range.
    //
    // The importance: a pixel's value is the mean radiance over its area A on the
    // plane at unit distance in front of the pinhole (a box filter over the pixel,
    // as jittered rays average), and dA = dw / cos^3(theta), theta the angle to the
    // viewing axis. A point source of intensity I at distance d then adds
    // I / (d^2 A cos^3 theta) to its pixel: `importance` is 1 / (A cos^3 theta).
    // Depths and clip distances are in world units along the viewing axis, as
    // generateRay's, so a sensor transform that is rigid up to a uniform scale or a
    // mirror (Mitsuba's <scale x="-1"/>) projects consistently; look-at ones are rigid.
    struct Projection {
        int x = 0, y = 0;  // image pixel (of the crop window when there is one)
        float offsetX = 0.0f, offsetY = 0.0f;  // where in that pixel, from its centre, in [-0.5, 0.5)
        Vec3 rayOrigin;    // where the camera ray towards p starts
        float distance = 0.0f;  // from the pinhole to p
        float importance = 0.0f;
    };
    std::optional<Projection> project(const Vec3& p) const;

    // OpenEXR's standard attributes, for row vectors (p' = p M, Imath's
    // convention). worldToCamera: into a left-handed camera space with +x to
    // the image's right, +y up and +z the viewing direction (Mitsuba's camera
    // space with x mirrored). worldToNDC: (x, y, z, w) with x/w, y/w in [0, 1]
    // from the image's top-left to its bottom-right corner (w = camera depth);
    // the image is the one written, so with a crop [0, 1] spans the crop window
    // and a world point lands on its pixel of the cropped EXR.
    Imath::M44f worldToCamera() const;
    Imath::M44f worldToNDC() const;

private:
    Transform worldFromCamera_;
    Transform cameraFromWorld_;
    Vec3 position_;
    Vec3 viewAxis_;  // unit world direction of camera-space +z
    int width_, height_;  // the film
    std::optional<FilmCrop> crop_;
    float tanHalfX_, tanHalfY_;
    float nearClip_, farClip_;
};

}  // namespace vrl
