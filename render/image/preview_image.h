// Preview images: an 8-bit sRGB PNG of a linear HDR Image, for people to look at
// (a web page, a test report), never for measurements, which use the EXR.
// Tone mapping is deliberately simple: multiply by 2^exposureStops, clamp each
// component to [0, 1] (NaN -> 0), apply the sRGB opto-electronic transfer
// function (IEC 61966-2-1) and round to 8 bits.
#pragma once

#include "render/image/image.h"

#include <filesystem>

namespace vrl {

// Writes `image` tone-mapped as above to `png` (always PNG, whatever the
// extension), RGB, 8 bits per channel, row 0 at the top like the Image. The file
// is written to "<png>.tmp" and renamed onto `png`, so a reader never sees a
// partial file. Throws std::invalid_argument for an empty image and
// std::runtime_error naming the path and OpenImageIO's message on I/O failure.
void writePreviewPng(const Image& image, const std::filesystem::path& png, float exposureStops = 0.0f);

// Exposure in stops that maps the 99th-percentile pixel luminance (Rec. 709
// weights, over all pixels, non-finite ones counted as 0) to a linear 0.9
// (display value about 0.95), so at most about 1% of pixels clip. If that
// percentile is 0 the brightest pixel is used instead; an empty or all-black
// image gives 0. The result is clamped to [-30, 30] stops.
float autoExposure(const Image& image);

}  // namespace vrl
