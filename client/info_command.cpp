// `vrl info IMAGE.exr`: what an EXR holds (size, layers with their channels,
// every vrl.* attribute), so that a user (or a test) can see how an image was
// made without another tool.
#include "client/commands.h"

#include "render/image/exr_io.h"

#include <cstdio>
#include <memory>
#include <string>

namespace vrl::client {

void registerInfoCommand(CLI::App& app, int& exitCode) {
    auto* cmd = app.add_subcommand("info", "Print an EXR image's size, layers and metadata (how it was rendered)");
    auto path = std::make_shared<std::string>();
    cmd->add_option("image", *path, "EXR image")->required()->check(CLI::ExistingFile);
    cmd->callback([path, &exitCode] {
        try {
            const ImageSet images = readExr(*path);
            std::printf("image    %s\nsize     %dx%d\n", path->c_str(), images.image.width(), images.image.height());
            std::printf("layer    (image) R G B\n");
            for (const auto& [name, layer] : images.layers)
                std::printf("layer    %s %s\n", name.c_str(),
                            images.singleChannelLayers.count(name) ? (name + ".Y").c_str()
                                                                   : (name + ".R " + name + ".G " + name + ".B").c_str());
            for (const auto& [key, value] : images.metadata)
                std::printf("%-28s %s\n", key.c_str(), metadataText(value).c_str());
            exitCode = 0;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "vrl info: error: %s\n", e.what());
            exitCode = 1;
        }
    });
}

}  // namespace vrl::client
