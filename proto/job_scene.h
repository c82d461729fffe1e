// A job's scene and settings from its spec and bundle. The coordinator and
// every worker call loadJobScene on the same bundle and spec, so they resolve
// the same resolution, sample count and render settings: pixels agree.
#pragma once

#include "proto/service_limits.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "vrl/v1/vrl.pb.h"

#include <filesystem>
#include <memory>
#include <stdexcept>

namespace vrl::rpc {

// A spec the service refuses (bad parameter, over a limit); the message says which.
struct JobSpecError : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

struct JobScene {
    std::unique_ptr<Scene> scene;
    RenderSettings settings;
    int width = 0, height = 0;
};

// Checks parameters that need no scene (method, counts, tile size) against the limits.
void validateJobSpec(const v1::JobSpec& spec, const ServiceLimits& limits);

// Parses `sceneFile` confined to `bundleDirectory`, applies the spec's defines
// and overrides, checks the limits and builds the scene. Throws JobSpecError,
// SceneError or std::runtime_error.
JobScene loadJobScene(const std::filesystem::path& bundleDirectory, const std::filesystem::path& sceneFile,
                      const v1::JobSpec& spec, const ServiceLimits& limits);

// RenderSettings' defaults as parameters: the scene's spp and depth, all four
// transport parts, the default VRL count and cut settings.
v1::RenderParameters defaultRenderParameters(const std::string& method);

// The tile side a spec asks for (0: 32).
int jobTileSize(const v1::JobSpec& spec);

}  // namespace vrl::rpc
