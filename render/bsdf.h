// Bsdf: the surface models of the scene subset. Diffuse (Lambertian, one-sided
// unless twoSided: black seen from the back, as Mitsuba) and Null (an invisible
// boundary between two media: rays pass straight through).
#pragma once

#include "render/rgb.h"

namespace vrl {

struct Bsdf {
    enum class Kind { Diffuse, Null };
    Kind kind = Kind::Diffuse;
    Rgb reflectance{0.5f};
    bool twoSided = false;

    bool isNull() const { return kind == Kind::Null; }
};

}  // namespace vrl
