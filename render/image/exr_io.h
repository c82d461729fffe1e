// EXR input/output for ImageSet: the image as 32-bit float channels R, G, B,
// each layer as "<name>.R", "<name>.G", "<name>.B" (a single-channel layer as
// "<name>.Y"), and the metadata as typed
// attributes of the header (string, int, float, double, M44f).
#pragma once

#include "render/image/image.h"

#include <filesystem>

namespace vrl {

// Writes `images` to `path` as a single-part scanline EXR, ZIP compressed, with
// data and display window (0,0)-(width-1,height-1). Every metadata entry becomes
// an attribute of its type under its key (e.g. "vrl.scene": string, "vrl.spp": int).
// The file is written to a temporary sibling and renamed onto `path`
// (util/atomic_file.h), so `path` is either left untouched or replaced by a
// complete file.
// Throws std::invalid_argument (naming the path) for an empty image, a layer
// whose size differs from the image, an empty or duplicate layer name, a
// single-channel name that is no layer, a name
// or key longer than OpenEXR's 255 characters, or the key "type" (OpenEXR's
// part type); std::runtime_error naming the path for any I/O or OpenEXR
// failure (e.g. a missing directory, a key naming a standard attribute).
// `pixels`: the channels' type; Half (16-bit, relative precision 2^-11, largest
// 65504) halves the file for images that need no more, e.g. cached references;
// it throws std::invalid_argument for a value beyond half's range.
enum class ExrPixels { Float, Half };
void writeExr(const std::filesystem::path& path, const ImageSet& images, ExrPixels pixels = ExrPixels::Float);

// Reads the first part of an EXR file, whichever tool wrote it: channels
// R, G, B (or, if none of them is present, a single Y channel as grey) into
// `image`; every complete "<layer>.R/.G/.B" triple, and every lone "<layer>.Y"
// (listed in singleChannelLayers, grey in memory), into `layers`, ordered by
// layer name (EXR stores channels sorted); every string attribute except the
// part "type", and every int, float, double and M44f attribute whose name starts
// with "vrl." or is worldToCamera / worldToNDC, into `metadata`. Other channels and attributes are ignored.
// Half and uint channels are converted to float. Pixel (0,0) is the data
// window's top-left corner, whatever its offset.
// Throws std::runtime_error with the path and OpenEXR's message for a missing,
// corrupt or truncated file, or one lacking some of R, G, B (named).
ImageSet readExr(const std::filesystem::path& path);

}  // namespace vrl
