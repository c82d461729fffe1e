// PerspectiveCamera: Mitsuba's perspective sensor. Camera space looks along +z
// with +y up and +x to the image's left; film coordinates run from the top-left
// corner, (x + 0.5, y + 0.5) being the centre of pixel (x, y). Rays start at the
// near clip plane and end at the far clip plane, as in Mitsuba.
#pragma once

#include "render/geometry.h"
#include "render/scene_description.h"

namespace vrl {

class PerspectiveCamera {
public:
    explicit PerspectiveCamera(const SensorDescription& sensor);

    int width() const { return width_; }
    int height() const { return height_; }
    Vec3 position() const { return position_; }
    // Primary ray through film position (filmX, filmY) in pixels.
    Ray generateRay(float filmX, float filmY) const;

private:
    Transform worldFromCamera_;
    Vec3 position_;
    int width_, height_;
    float tanHalfX_, tanHalfY_;
    float nearClip_, farClip_;
};

}  // namespace vrl
