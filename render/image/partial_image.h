// Partial images: what an interrupted render keeps.
//
// Contract: markPartial turns the ImageSet of a render that stopped early (its
// unfinished pixels zero in every layer) into a self-describing partial image:
// a single-channel layer "coverage" (1 where a finished tile covers the pixel,
// 0 elsewhere) and the EXR attributes `vrl.partial` (int: tiles finished) and
// `vrl.tilesTotal` (int). A complete image has neither, so readers tell the two
// apart by `vrl.partial` alone. Throws std::invalid_argument when `covered` does
// not hold one entry per pixel or the tile counts are inconsistent.
#pragma once

#include "render/image/image.h"

#include <cstdint>
#include <vector>

namespace vrl {

inline constexpr const char* kCoverageLayer = "coverage";
inline constexpr const char* kPartialKey = "vrl.partial";
inline constexpr const char* kTilesTotalKey = "vrl.tilesTotal";

// `covered`: per pixel, row-major from the top left, non-zero where finished.
void markPartial(ImageSet& images, const std::vector<uint8_t>& covered, int tilesDone, int tilesTotal);

}  // namespace vrl
