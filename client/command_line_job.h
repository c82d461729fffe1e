// The job of a `vrl render` or `vrl submit` command line, resolved once before
// any work is spent and then carried to where it runs: the embedded render
// builds its scene from it, `--workers` and `vrl submit` send its spec and
// bundle its files. So the scene is parsed once, the -D defines read once and
// the outputs checked once, and everything that would refuse the job refuses
// it before a process starts or a byte is uploaded.
#pragma once

#include "client/render_options.h"
#include "service/job/job_scene.h"
#include "vrl/v1/vrl.pb.h"

#include <filesystem>
#include <vector>

namespace vrl::client {

struct CommandLineJob {
    v1::JobSpec spec;           // the flags' spec (makeJobSpec): no priority, no bundle yet
    rpc::ResolvedJob resolved;  // the parsed scene and its RenderSettings, as the coordinator resolves them
    // The scene and every file it reads (includes, meshes, textures), as the parse
    // met them: the files of the job's bundle.
    std::vector<std::filesystem::path> sceneFiles;
};

// Resolves the command line in this order, the first refusal thrown (exit 2):
//  1. the outputs at once, from file-system metadata (checkOutputPaths with the scene file);
//  2. the -D defines (util::parseDefines);
//  3. the scene, parsed with them (SceneError, e.g. a -D the scene does not use);
//  4. the outputs against every file the scene reads (checkOutputsAreNotInputs);
//  5. the flags into the spec (makeJobSpec: --resolution, --crop);
//  6. the spec against the scene by the coordinator's own builder
//     (rpc::resolveParsedJob: method, crop, medium, counts; rpc::JobSpecError),
//     with the command line's light limit (2^40) in place of a coordinator's.
CommandLineJob resolveCommandLineJob(const RenderCommandOptions& o);

}  // namespace vrl::client
