// PerspectiveCamera: Mitsuba's perspective sensor. Camera space looks along +z
// with +y up and +x to the image's left; film coordinates run from the top-left
// corner, (x + 0.5, y + 0.5) being the centre of pixel (x, y). Rays start at the
// near clip plane and end at the far clip plane, as in Mitsuba.
#pragma once

#include "render/core/geometry.h"
#include "render/scene/scene_description.h"

#include <Imath/ImathMatrix.h>

namespace vrl {

class PerspectiveCamera {
public:
    explicit PerspectiveCamera(const SensorDescription& sensor);

    int width() const { return width_; }
    int height() const { return height_; }
    Vec3 position() const { return position_; }
    // Primary ray through film position (filmX, filmY) in pixels.
    Ray generateRay(float filmX, float filmY) const;

    // OpenEXR's standard attributes, for row vectors (p' = p M, Imath's
    // convention). worldToCamera: into a left-handed camera space with +x to
    // the image's right, +y up and +z the viewing direction (Mitsuba's camera
    // space with x mirrored). worldToNDC: (x, y, z, w) with x/w, y/w in [0, 1]
    // from the image's top-left to its bottom-right corner (w = camera depth).
    Imath::M44f worldToCamera() const;
    Imath::M44f worldToNDC() const;

private:
    Transform worldFromCamera_;
    Vec3 position_;
    int width_, height_;
    float tanHalfX_, tanHalfY_;
    float nearClip_, farClip_;
};

}  // namespace vrl
