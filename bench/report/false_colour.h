// False-colour pictures of per-pixel counters (#Eval, #Inter; Vibert et al.
// 2019, Figure 6), auto-exposed as in the paper: the values are sorted and the
// scale clipped at a percentile, then mapped through a perceptual colour ramp
// (dark blue -> green -> yellow, viridis-like).
#pragma once

#include "render/image/image.h"

#include <filesystem>

namespace vrl::report {

// The value at `percentile` (0..1) of the image's first channel, finite values only; 0 if none.
float percentileValue(const Image& counts, float percentile);

// Writes counts (first channel) as an 8-bit PNG, values at or above
// `clipAt` in the brightest colour. Returns clipAt for the caption.
void writeFalseColourPng(const Image& counts, float clipAt, const std::filesystem::path& png);

}  // namespace vrl::report
