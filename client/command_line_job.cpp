#include "client/command_line_job.h"

#include "client/output_checks.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "util/command_line.h"

#include <utility>

namespace vrl::client {

CommandLineJob resolveCommandLineJob(const RenderCommandOptions& o) {
    checkOutputPaths(o.output, o.preview, {o.scene});
    CommandLineJob job;
    ParseOptions options;
    options.defines = util::parseDefines(o.defines);
    options.onFileReferenced = [&](const std::filesystem::path& file) { job.sceneFiles.push_back(file); };
    SceneDescription description = parseMitsubaScene(o.scene, options);
    checkOutputsAreNotInputs(o.output, o.preview, job.sceneFiles);
    job.spec = makeJobSpec(o, options.defines);
    rpc::ServiceLimits limits;
    limits.maxVrls = uint64_t(1) << 40;  // the memory check (checkLightMemory), not a coordinator's limit, bounds it here
    job.resolved = rpc::resolveParsedJob(std::move(description), job.spec, limits);
    return job;
}

}  // namespace vrl::client
