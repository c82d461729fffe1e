#include "render/sample_sums.h"

#include "render/integrators/transport_parts.h"

#include <algorithm>
#include <stdexcept>

namespace vrl {

namespace {

bool isTransportPart(const std::string& name) {
    return std::find(kTransportPartNames.begin(), kTransportPartNames.end(), name) != kTransportPartNames.end() ||
           name == kSurfaceVplLayerName;
}

void checkSameShape(const SampleSums& a, const SampleSums& b) {
    if (a.layers.size() != b.layers.size() || a.perPixel != b.perPixel)
        throw std::invalid_argument("sample sums differ in their layers");
    if (a.layers.size() != a.perPixel.size()) throw std::invalid_argument("sample sums: one flag per layer expected");
}

}  // namespace

SampleSums SampleSums::zeros(int width, int height, const std::vector<uint8_t>& perPixel) {
    SampleSums sums;
    sums.layers.assign(perPixel.size(), Image(width, height));
    sums.perPixel = perPixel;
    return sums;
}

void addPass(SampleSums& into, const SampleSums& pass) {
    checkSameShape(into, pass);
    for (size_t l = 0; l < into.layers.size(); ++l) {
        Image& a = into.layers[l];
        const Image& b = pass.layers[l];
        if (a.width() != b.width() || a.height() != b.height())
            throw std::invalid_argument("sample sums differ in size");
        if (into.perPixel[l]) continue;
        for (size_t i = 0; i < a.pixelCount(); ++i) a[i] += b[i];
    }
    into.boundExceeded += pass.boundExceeded;
    into.boundedEstimates += pass.boundedEstimates;
}

void copyRows(SampleSums& into, const SampleSums& tile, int x0, int y0, int rows) {
    checkSameShape(into, tile);
    for (size_t l = 0; l < into.layers.size(); ++l) {
        const Image& from = tile.layers[l];
        Image& to = into.layers[l];
        if (x0 < 0 || y0 < 0 || rows < 0 || rows > from.height() || x0 + from.width() > to.width() ||
            y0 + rows > to.height())
            throw std::invalid_argument("copyRows: the tile does not fit");
        for (int y = 0; y < rows; ++y) std::copy_n(&from.at(0, y), from.width(), &to.at(x0, y0 + y));
    }
}

std::vector<Image> resolveSamples(const SampleSums& sums, const std::vector<std::string>& layerNames, int samples) {
    if (sums.layers.size() != layerNames.size() + 1 || sums.perPixel.size() != sums.layers.size())
        throw std::invalid_argument("resolveSamples: layer count mismatch");
    if (samples < 1) throw std::invalid_argument("resolveSamples: at least one sample per pixel");
    const float n = float(samples);
    std::vector<Image> layers;
    layers.reserve(sums.layers.size());
    for (size_t l = 0; l < sums.layers.size(); ++l) {
        const Image& sum = sums.layers[l];
        Image mean(sum.width(), sum.height());
        for (size_t i = 0; i < sum.pixelCount(); ++i) mean[i] = sums.perPixel[l] ? sum[i] : sum[i] / n;
        layers.push_back(std::move(mean));
    }
    for (size_t l = 0; l < layerNames.size(); ++l) {
        if (!isTransportPart(layerNames[l])) continue;
        for (size_t i = 0; i < layers[0].pixelCount(); ++i) layers[0][i] += layers[l + 1][i];
    }
    return layers;
}

}  // namespace vrl
