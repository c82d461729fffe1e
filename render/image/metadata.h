// Metadata of an image: typed values for the EXR header. Numbers are written
// as int or float attributes (as pbrt-v4 writes renderTimeSeconds and
// samplesPerPixel), text as strings, and the camera's matrices as M44f
// (OpenEXR's standard worldToCamera / worldToNDC), so that tools that read
// headers (compositors, exrheader, our report) get numbers, not text.
#pragma once

#include <Imath/ImathMatrix.h>

#include <cstdint>
#include <map>
#include <string>
#include <variant>

namespace vrl {

using MetadataValue = std::variant<std::string, int32_t, float, double, Imath::M44f>;
using Metadata = std::map<std::string, MetadataValue>;

// The value as text, for logs and comparisons ("0.25", "[[1 0 0 0] ...]").
std::string metadataText(const MetadataValue& value);

// The value as a number: int, float or double as is, a string parsed as a
// decimal; throws std::invalid_argument for text that is no number or a matrix.
double metadataNumber(const MetadataValue& value);

}  // namespace vrl
