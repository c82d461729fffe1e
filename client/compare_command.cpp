#include "client/commands.h"

#include "render/image/exr_io.h"
#include "render/image/image_metrics.h"
#include "render/image/partial_image.h"

#include <cstdio>
#include <cstring>
#include <memory>
#include <set>
#include <string>
#include <utility>

namespace vrl::client {

void registerCompareCommand(CLI::App& app, int& exitCode) {
    auto* cmd = app.add_subcommand("compare", "Compare an image with a reference: RMSE, relative RMSE, SMAPE on luminance");
    auto paths = std::make_shared<std::pair<std::string, std::string>>();
    auto exact = std::make_shared<bool>(false);
    cmd->add_flag("--exact", *exact,
                  "Also require bit-identical pixels in the image and every layer (same layer names); exit 1 "
                  "otherwise. Metadata (timings) is ignored.");
    auto metadata = std::make_shared<bool>(false);
    cmd->add_flag("--metadata", *metadata,
                  "Also require the same metadata keys and values, apart from timings (vrl.time.*) and how the "
                  "render ran (vrl.run.*: threads, workers, job id); prints each difference; exit 1 otherwise.");
    cmd->add_option("reference", paths->first, "Reference EXR image")->required()->check(CLI::ExistingFile);
    cmd->add_option("image", paths->second, "EXR image to evaluate")->required()->check(CLI::ExistingFile);
    cmd->footer(
        "Metrics on per-pixel luminance L = 0.2127 R + 0.7152 G + 0.0722 B, over n pixels:\n"
        "  RMSE          = sqrt(mean((I - R)^2))\n"
        "  relative RMSE = sqrt(mean((I - R)^2 / (R^2 + 0.01)))\n"
        "  SMAPE         = (2/n) sum |R - I| / (R + I + 0.01)   (Vibert et al. 2019)\n"
        "  mean luminance of the image, of the reference, and their ratio\n"
        "Exits 1 when the sizes differ or a file cannot be read.");
    cmd->callback([paths, exact, metadata, &exitCode] {
        try {
            const ImageSet reference = readExr(paths->first);
            const ImageSet image = readExr(paths->second);
            // A partial render (interrupted) is compared like any image, but say so: its missing tiles are zero.
            for (const auto& [path, set] : {std::pair{&paths->first, &reference}, std::pair{&paths->second, &image}}) {
                const auto partial = set->metadata.find(kPartialKey), total = set->metadata.find(kTilesTotalKey);
                if (partial != set->metadata.end())
                    std::fprintf(stderr, "note: %s is a partial render: %s of %s tiles (unfinished pixels are 0)\n",
                                 path->c_str(), metadataText(partial->second).c_str(),
                                 total != set->metadata.end() ? metadataText(total->second).c_str() : "?");
            }
            const ImageErrorMetrics m = compareImages(reference.image, image.image);
            std::printf("pixels         %zu\n", m.pixels);
            std::printf("RMSE           %.6g\n", m.rmse);
            std::printf("relative RMSE  %.6g\n", m.relativeRmse);
            std::printf("SMAPE          %.6g\n", m.smape);
            std::printf("mean luminance %.6g (reference %.6g, ratio %.4f)\n", m.meanTest, m.meanReference,
                        m.meanReference != 0.0 ? m.meanTest / m.meanReference : 0.0);
            if (m.nonFinitePixels > 0) {
                std::printf("non-finite     %zu pixels (excluded from the sums)\n", m.nonFinitePixels);
                exitCode = 1;
            }
            if (*exact) {
                size_t differing = 0;
                auto count = [&](const Image& a, const Image& b) {
                    for (size_t i = 0; i < a.pixelCount(); ++i)
                        if (std::memcmp(&a[i], &b[i], sizeof(Rgb)) != 0) ++differing;
                };
                count(reference.image, image.image);
                bool sameLayers = reference.layers.size() == image.layers.size();
                for (size_t l = 0; sameLayers && l < reference.layers.size(); ++l) {
                    const auto& [nameA, a] = reference.layers[l];
                    const auto& [nameB, b] = image.layers[l];
                    sameLayers = nameA == nameB && a.width() == b.width() && a.height() == b.height();
                    if (sameLayers) count(a, b);
                }
                if (!sameLayers) {
                    std::printf("identical      no (the layers differ in names or sizes)\n");
                    exitCode = 1;
                } else if (differing > 0) {
                    std::printf("identical      no (%zu pixel values differ over image and %zu layers)\n", differing,
                                reference.layers.size());
                    exitCode = 1;
                } else {
                    std::printf("identical      yes (image and %zu layers, bit for bit)\n", reference.layers.size());
                }
            }
            if (*metadata) {
                const auto compared = [](const std::string& key) {
                    return key.rfind("vrl.time.", 0) != 0 && key.rfind("vrl.run.", 0) != 0;
                };
                size_t differences = 0, keys = 0;
                std::set<std::string> all;
                for (const auto& [key, value] : reference.metadata) all.insert(key);
                for (const auto& [key, value] : image.metadata) all.insert(key);
                for (const auto& key : all) {
                    if (!compared(key)) continue;
                    ++keys;
                    const auto a = reference.metadata.find(key), b = image.metadata.find(key);
                    if (a != reference.metadata.end() && b != image.metadata.end() && a->second == b->second) continue;
                    ++differences;
                    std::printf("metadata       %s: %s vs %s\n", key.c_str(),
                                a == reference.metadata.end() ? "(absent)" : metadataText(a->second).c_str(),
                                b == image.metadata.end() ? "(absent)" : metadataText(b->second).c_str());
                }
                if (differences > 0) {
                    std::printf("same metadata  no (%zu of %zu keys differ; vrl.time.* and vrl.run.* not compared)\n",
                                differences, keys);
                    exitCode = 1;
                } else {
                    std::printf("same metadata  yes (%zu keys; vrl.time.* and vrl.run.* not compared)\n", keys);
                }
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "vrl compare: error: %s\n", e.what());
            exitCode = 1;
        }
    });
}

}  // namespace vrl::client
