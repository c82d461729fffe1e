// layer_variance: where an image's noise comes from. Given K renders of one
// job that differ only by --seed (EXRs written by `vrl render`, any version),
// prints for the image and each RGB layer (the transport parts): its mean
// luminance, the per-pixel variance over the K renders (averaged over the
// pixels, of luminance, unbiased with K - 1), the relative noise (the RMS of
// the per-pixel standard deviations over the mean), and its share of the sum
// of the parts' variances (the parts use different random numbers, so that
// sum is about the image's variance; the VRLs both VRL parts use are shared,
// and their covariance is the difference, printed too), and its brightest
// pixel in any run (a firefly shows there first). Counter layers
// (single-channel) are skipped.
#include "render/image/exr_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

using namespace vrl;

namespace {

double luminanceOf(const Rgb& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

struct LayerNoise {
    double mean = 0.0, variance = 0.0;
    double largest = 0.0;  // the brightest pixel of any run (fireflies)
};

LayerNoise noiseOf(const std::vector<const Image*>& runs) {
    const size_t k = runs.size(), n = runs[0]->pixelCount();
    LayerNoise out;
    for (size_t p = 0; p < n; ++p) {
        double sum = 0.0, sum2 = 0.0;
        for (const Image* run : runs) {
            const double y = luminanceOf((*run)[p]);
            out.largest = std::max(out.largest, y);
            sum += y;
            sum2 += y * y;
        }
        const double mean = sum / double(k);
        out.mean += mean;
        out.variance += std::max(0.0, (sum2 - double(k) * mean * mean) / double(k - 1));
    }
    out.mean /= double(n);
    out.variance /= double(n);
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: layer_variance RUN1.exr RUN2.exr [...]  (renders of one job, different seeds)\n");
        return 2;
    }
    std::vector<ImageSet> runs;
    try {
        for (int i = 1; i < argc; ++i) runs.push_back(readExr(argv[i]));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "layer_variance: %s\n", e.what());
        return 1;
    }
    for (const ImageSet& run : runs) {
        if (run.image.width() != runs[0].image.width() || run.image.height() != runs[0].image.height() ||
            run.layers.size() != runs[0].layers.size()) {
            std::fprintf(stderr, "layer_variance: the files are not renders of one job (sizes or layers differ)\n");
            return 2;
        }
    }
    std::vector<const Image*> images;
    for (const ImageSet& run : runs) images.push_back(&run.image);
    const LayerNoise image = noiseOf(images);
    std::vector<std::pair<std::string, LayerNoise>> parts;
    double partsVariance = 0.0;
    for (size_t l = 0; l < runs[0].layers.size(); ++l) {
        const std::string& name = runs[0].layers[l].first;
        if (runs[0].singleChannelLayers.count(name)) continue;
        std::vector<const Image*> layer;
        for (const ImageSet& run : runs) layer.push_back(&run.layers[l].second);
        parts.emplace_back(name, noiseOf(layer));
        partsVariance += parts.back().second.variance;
    }
    std::printf("%zu runs, %dx%d\n", runs.size(), runs[0].image.width(), runs[0].image.height());
    std::printf("%-16s %12s %12s %12s %10s %12s\n", "layer", "mean", "variance", "rel. noise", "share", "brightest");
    const auto row = [&](const std::string& name, const LayerNoise& n, double share) {
        std::printf("%-16s %12.5g %12.5g %12.4f %9.1f%% %12.5g\n", name.c_str(), n.mean, n.variance,
                    n.mean > 0.0 ? std::sqrt(n.variance) / n.mean : 0.0, 100.0 * share, n.largest);
    };
    row("(image)", image, partsVariance > 0.0 ? image.variance / partsVariance : 0.0);
    for (const auto& [name, n] : parts) row(name, n, partsVariance > 0.0 ? n.variance / partsVariance : 0.0);
    std::printf("image variance - sum of the parts' variances (2 x covariances): %.4g\n", image.variance - partsVariance);
    return 0;
}
