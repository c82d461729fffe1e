// Bit-exact image comparisons for the determinism tests: the same job must give
// the same bits whatever the threads, tiles, passes or VRL-set order.
#pragma once

#include "render/image/image.h"

#include <gtest/gtest.h>

#include <cstring>

namespace vrl::test {

// Same size and the same bits in every pixel (memcmp: -0 and NaN payloads count).
inline bool bitIdentical(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.pixels().data(), b.pixels().data(), a.pixelCount() * sizeof(Rgb)) == 0;
}

// The image and every layer, by name and in order, bit for bit.
inline ::testing::AssertionResult sameLayers(const ImageSet& a, const ImageSet& b) {
    if (!bitIdentical(a.image, b.image)) return ::testing::AssertionFailure() << "the image differs";
    if (a.layers.size() != b.layers.size()) return ::testing::AssertionFailure() << "layer counts differ";
    for (size_t l = 0; l < a.layers.size(); ++l)
        if (a.layers[l].first != b.layers[l].first || !bitIdentical(a.layers[l].second, b.layers[l].second))
            return ::testing::AssertionFailure() << "layer " << a.layers[l].first << " differs";
    return ::testing::AssertionSuccess();
}

}  // namespace vrl::test
