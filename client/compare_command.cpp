#include "client/commands.h"

#include "render/exr_io.h"
#include "render/image_metrics.h"

#include <cstdio>
#include <memory>

namespace vrl {

void registerCompareCommand(CLI::App& app, int& exitCode) {
    auto* cmd = app.add_subcommand("compare", "Compare an image with a reference: RMSE, relative RMSE, SMAPE on luminance");
    auto paths = std::make_shared<std::pair<std::string, std::string>>();
    cmd->add_option("reference", paths->first, "Reference EXR image")->required()->check(CLI::ExistingFile);
    cmd->add_option("image", paths->second, "EXR image to evaluate")->required()->check(CLI::ExistingFile);
    cmd->footer(
        "Metrics on per-pixel luminance L = 0.2127 R + 0.7152 G + 0.0722 B, over n pixels:\n"
        "  RMSE          = sqrt(mean((I - R)^2))\n"
        "  relative RMSE = sqrt(mean((I - R)^2 / (R^2 + 0.01)))\n"
        "  SMAPE         = (2/n) sum |R - I| / (R + I + 0.01)   (Vibert et al. 2019)\n"
        "Exits 1 when the sizes differ or a file cannot be read.");
    cmd->callback([paths, &exitCode] {
        try {
            const ImageSet reference = readExr(paths->first);
            const ImageSet image = readExr(paths->second);
            const ImageErrorMetrics m = compareImages(reference.image, image.image);
            std::printf("pixels         %zu\n", m.pixels);
            std::printf("RMSE           %.6g\n", m.rmse);
            std::printf("relative RMSE  %.6g\n", m.relativeRmse);
            std::printf("SMAPE          %.6g\n", m.smape);
            if (m.nonFinitePixels > 0) {
                std::printf("non-finite     %zu pixels (excluded from the sums)\n", m.nonFinitePixels);
                exitCode = 1;
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "vrl compare: error: %s\n", e.what());
            exitCode = 1;
        }
    });
}

}  // namespace vrl
