// service/job/: turning a job into a render: scene bundles and the one builder of
// RenderSettings from a job spec.
//
// A job's scene and settings from its spec: the one builder of RenderSettings.
// The coordinator and every worker call loadJobScene on the same bundle and
// spec, and `vrl render` calls resolveJob on the spec it builds from its flags,
// so all of them resolve the same resolution, sample count and settings:
// pixels and metadata agree however a job runs.
#pragma once

#include "render/renderer.h"
#include "render/scene/scene.h"
#include "render/description/scene_description.h"
#include "service/common/limits.h"
#include "vrl/v1/vrl.pb.h"

#include <filesystem>
#include <memory>
#include <stdexcept>

namespace vrl::rpc {

// A spec the service refuses (bad parameter, over a limit); the message says which.
struct JobSpecError : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

// A job resolved against its scene file, before the scene is built.
struct ResolvedJob {
    SceneDescription description;  // parsed, defines applied, --medium filled, resolution and crop overridden
    RenderSettings settings;
};

struct JobScene {
    std::unique_ptr<Scene> scene;
    RenderSettings settings;
    int width = 0, height = 0;  // the image: the crop window's size if there is one
};

// Checks parameters that need no scene (method, counts, tile size) against the limits.
void validateJobSpec(const v1::JobSpec& spec, const ServiceLimits& limits);

// Validates the spec, parses `sceneFile` (confined to `confineTo` unless it is
// empty), applies the spec's defines, fill medium, resolution and then crop
// window (relative to the resolved film; absent: the scene's, which must fit
// it), checks the limits and resolves the RenderSettings (the scene's spp and
// depth where the spec leaves them; with no method, the one the scene's
// <integrator type> names if it is one of renderMethodNames(), else
// kHeadlineMethod). Throws JobSpecError, SceneError or std::runtime_error.
ResolvedJob resolveJob(const std::filesystem::path& sceneFile, const v1::JobSpec& spec, const ServiceLimits& limits,
                       const std::filesystem::path& confineTo = {});

// resolveJob on a scene its caller parsed (parseMitsubaScene) with the spec's
// defines: `vrl render` parses the scene once, collecting the files it reads
// for the bundle, before its flags become a spec.
ResolvedJob resolveParsedJob(SceneDescription description, const v1::JobSpec& spec, const ServiceLimits& limits);

// resolveJob confined to `bundleDirectory`, then builds the scene.
JobScene loadJobScene(const std::filesystem::path& bundleDirectory, const std::filesystem::path& sceneFile,
                      const v1::JobSpec& spec, const ServiceLimits& limits);

// RenderSettings' defaults as parameters: the scene's spp and depth, all four
// transport parts, the default VRL count and cut settings.
v1::RenderParameters defaultRenderParameters(RenderMethod method);

// The tile side a spec asks for (0: 32).
int jobTileSize(const v1::JobSpec& spec);

}  // namespace vrl::rpc
