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
#include "render/scene/scene_description.h"

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
    Vec3 position_;
    int width_, height_;  // the film
    std::optional<FilmCrop> crop_;
    float tanHalfX_, tanHalfY_;
    float nearClip_, farClip_;
};

}  // namespace vrl
