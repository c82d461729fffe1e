#include "render/image/partial_image.h"

#include <stdexcept>
#include <string>

namespace vrl {

void markPartial(ImageSet& images, const std::vector<uint8_t>& covered, int tilesDone, int tilesTotal) {
    const Image& image = images.image;
    if (covered.size() != image.pixelCount())
        throw std::invalid_argument("markPartial: " + std::to_string(covered.size()) + " coverage entries for " +
                                    std::to_string(image.pixelCount()) + " pixels");
    if (tilesDone < 0 || tilesTotal < 1 || tilesDone > tilesTotal)
        throw std::invalid_argument("markPartial: " + std::to_string(tilesDone) + " of " + std::to_string(tilesTotal) +
                                    " tiles");
    Image coverage(image.width(), image.height());
    for (size_t i = 0; i < covered.size(); ++i) coverage[i] = Rgb(covered[i] ? 1.0f : 0.0f);
    for (const auto& entry : images.layers)
        if (entry.first == kCoverageLayer) throw std::invalid_argument("markPartial: the image already has a coverage layer");
    images.layers.emplace_back(kCoverageLayer, std::move(coverage));
    images.singleChannelLayers.insert(kCoverageLayer);
    images.metadata[kPartialKey] = int32_t(tilesDone);
    images.metadata[kTilesTotalKey] = int32_t(tilesTotal);
}

}  // namespace vrl
