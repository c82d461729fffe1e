// libFuzzer target: the scene-bundle reader (proto/scene_bundle.h) and what a
// worker does with a bundle it accepts.
//
// The input is a serialised vrl.v1.SceneBundle. vrl::rpc::parseBundleBlob
// validates it under the default ServiceLimits; a valid bundle is then
// extracted with extractBundle into a fresh directory and loaded as a worker
// loads a job (rpc::loadJobScene with the default "path" parameters: parse
// confined to the bundle, limits, Scene::build, which reads OBJ and .serialized
// meshes and textures from the bundle). The directory is removed afterwards.
//
// Documented refusals: parseBundleBlob throws rpc::BundleError; extractBundle
// std::runtime_error or std::filesystem::filesystem_error (names the system
// refuses, e.g. a component longer than 255 bytes); loadJobScene JobSpecError,
// SceneError or std::runtime_error. Anything else is reported with
// VRL_FUZZ_STRICT_EXCEPTIONS=1 (fuzz_common.h).
#include "fuzz/fuzz_common.h"
#include "service/job/job_scene.h"
#include "service/job/scene_bundle.h"

#include <google/protobuf/stubs/logging.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>

namespace {
vrl_fuzz::TempDir* gDirectory = nullptr;
uint64_t gCount = 0;
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    vrl_fuzz::quietLogs();
    google::protobuf::SetLogHandler(nullptr);  // e.g. "invalid UTF-8" for every such string field
    gDirectory = new vrl_fuzz::TempDir("vrl-fuzz-bundle");
    std::atexit([] { delete gDirectory; });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string blob(reinterpret_cast<const char*>(data), size);
    const vrl::rpc::ServiceLimits limits;
    vrl::v1::SceneBundle bundle;
    try {
        bundle = vrl::rpc::parseBundleBlob(blob, limits);
    } catch (const vrl::rpc::BundleError& e) {
        vrl_fuzz::refused("parseBundleBlob", e);
        return 0;
    } catch (const std::exception& e) {
        if (vrl_fuzz::strictExceptions()) vrl_fuzz::undocumented("parseBundleBlob", e);
        vrl_fuzz::refused("parseBundleBlob", e);
        return 0;
    }
    const std::filesystem::path directory = gDirectory->path() / ("b" + std::to_string(gCount++));
    try {
        const std::filesystem::path scene = vrl::rpc::extractBundle(bundle, directory);
        vrl::v1::JobSpec spec;
        *spec.mutable_parameters() = vrl::rpc::defaultRenderParameters(vrl::RenderMethod::Path);
        const vrl::rpc::JobScene job = vrl::rpc::loadJobScene(directory, scene, spec, limits);
        vrl_fuzz::accepted("bundle extracted, scene built");
    } catch (const std::runtime_error& e) {  // SceneError, filesystem_error
        vrl_fuzz::refused("extractBundle / loadJobScene", e);
    } catch (const vrl::rpc::JobSpecError& e) {
        vrl_fuzz::refused("loadJobScene", e);
    } catch (const std::exception& e) {
        if (vrl_fuzz::strictExceptions()) vrl_fuzz::undocumented("extractBundle / loadJobScene", e);
        vrl_fuzz::refused("extractBundle / loadJobScene", e);
    }
    std::error_code error;
    std::filesystem::remove_all(gDirectory->path(), error);  // the bundle and any half-extracted staging copy
    std::filesystem::create_directories(gDirectory->path(), error);
    return 0;
}
