// render/image/: images and what is done with them: layers and typed metadata,
// EXR input/output, PNG previews, error metrics.
//
// Image: a width x height grid of linear RGB values, row-major from the top-left
// pixel. ImageSet bundles the final image with named layers (AOVs, e.g. the
// transport parts) and typed metadata written into the EXR header (metadata.h).
#pragma once

#include "render/core/rgb.h"
#include "render/image/metadata.h"

#include <cstddef>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace vrl {

class Image {
public:
    Image() = default;
    Image(int width, int height) : width_(width), height_(height), pixels_(size_t(width) * height, Rgb(0.0f)) {}

    int width() const { return width_; }
    int height() const { return height_; }
    size_t pixelCount() const { return pixels_.size(); }

    Rgb& at(int x, int y) { return pixels_[size_t(y) * width_ + x]; }
    const Rgb& at(int x, int y) const { return pixels_[size_t(y) * width_ + x]; }
    Rgb& operator[](size_t i) { return pixels_[i]; }
    const Rgb& operator[](size_t i) const { return pixels_[i]; }
    const std::vector<Rgb>& pixels() const { return pixels_; }

private:
    int width_ = 0;
    int height_ = 0;
    std::vector<Rgb> pixels_;
};

struct ImageSet {
    Image image;                                // the final image ("R", "G", "B" channels)
    std::vector<std::pair<std::string, Image>> layers;  // written as "<name>.R" etc.
    // Layers that hold one number per pixel (counters such as "eval", the
    // "coverage" of a partial render): kept grey (R = G = B) in memory, written
    // as the single channel "<name>.Y".
    std::set<std::string> singleChannelLayers;
    Metadata metadata;  // EXR header attributes
};

}  // namespace vrl
