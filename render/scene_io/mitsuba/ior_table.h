// Named optical constants that Mitsuba 0.5 scenes may give instead of numbers:
//  - the dielectric index-of-refraction table accepted by intIOR/extIOR/extEta
//    (Mitsuba's src/bsdfs/ior.h: Hecht, Optics, 4th ed.; 0-20 degrees C at
//    ~589 nm), matched case-insensitively as Mitsuba does;
//  - the conductor presets of the `material` parameter as complex indices
//    eta + i k per linear-sRGB channel: Mitsuba's measured spectra
//    (data/ior/<name>.eta.spd / .k.spd) projected to RGB, the same numbers as
//    Tungsten's ComplexIorData. Matched exactly (they are file names in
//    Mitsuba), except "none": eta 0, k 1, Mitsuba's perfect mirror.
// Values are absolute (relative to vacuum).
#pragma once

#include <optional>
#include <span>
#include <string_view>

#include "render/core/rgb.h"

namespace vrl {

struct NamedIor {
    std::string_view name;
    float value;
};

struct ConductorPreset {
    std::string_view name;
    Rgb eta;
    Rgb k;
};

// Mitsuba's table, in its order (for error messages listing the names).
std::span<const NamedIor> dielectricIors();
std::optional<float> lookupDielectricIor(std::string_view name);

// "none" first, then Mitsuba's presets in alphabetical order.
std::span<const ConductorPreset> conductorPresets();
std::optional<ConductorPreset> lookupConductorPreset(std::string_view name);

}  // namespace vrl
