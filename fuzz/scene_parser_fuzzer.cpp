// libFuzzer target: the Mitsuba XML scene parser, then Scene::build on what it
// accepts.
//
// The input is the scene text. It is parsed as vrl::parseMitsubaSceneString
// against an empty private directory, confined to it (as job bundles are), so
// no include, mesh or texture can be found and nothing outside is ever read:
// the target exercises the XML, value, plugin and reference handling, then the
// construction of the render scene (media, emitters, built-in shapes, camera,
// Embree BVH).
//
// Documented refusals: parse throws vrl::SceneError; Scene::build throws
// vrl::SceneError or std::runtime_error (Embree). Anything else is reported
// with VRL_FUZZ_STRICT_EXCEPTIONS=1 (fuzz_common.h).
#include "fuzz/fuzz_common.h"
#include "render/scene/scene.h"
#include "render/description/scene_error.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace {
vrl_fuzz::TempDir* gDirectory = nullptr;
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    vrl_fuzz::quietLogs();
    gDirectory = new vrl_fuzz::TempDir("vrl-fuzz-scene");
    std::atexit([] { delete gDirectory; });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string xml(reinterpret_cast<const char*>(data), size);
    vrl::ParseOptions options;
    options.confineTo = gDirectory->path();
    vrl::SceneDescription description;
    try {
        description = vrl::parseMitsubaSceneString(xml, gDirectory->path(), options, "fuzz.xml");
    } catch (const vrl::SceneError& e) {
        vrl_fuzz::refused("parseMitsubaSceneString", e);
        return 0;
    } catch (const std::exception& e) {
        if (vrl_fuzz::strictExceptions()) vrl_fuzz::undocumented("parseMitsubaSceneString", e);
        vrl_fuzz::refused("parseMitsubaSceneString", e);
        return 0;
    }
    try {
        const std::unique_ptr<vrl::Scene> scene = vrl::Scene::build(description);
        vrl_fuzz::accepted("scene built");
    } catch (const std::runtime_error& e) {  // SceneError is one
        vrl_fuzz::refused("Scene::build", e);
    } catch (const std::exception& e) {
        if (vrl_fuzz::strictExceptions()) vrl_fuzz::undocumented("Scene::build", e);
        vrl_fuzz::refused("Scene::build", e);
    }
    return 0;
}
