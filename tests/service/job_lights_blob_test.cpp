// The one codec of a job's lights blob (service/job/job_lights_blob.h), as the
// coordinator encodes and a worker decodes it: for every kind of blob (a VRL
// set, a tree, several trees, each with and without part (b)'s surface VPLs,
// part (b) alone) the decoded lights encode to the same bytes and shade a tile
// bit for bit as the lights prepared in process do; a blob that does not fit
// the job's settings is refused with a message naming what is wrong.
#include "service/job/job_lights_blob.h"

#include "render/lightcuts/tree/light_tree_io.h"
#include "render/scene/scene.h"
#include "tests/support/image_compare.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace vrl {
namespace {

RenderSettings settingsFor(RenderMethod method) {
    RenderSettings settings;
    settings.method = method;
    settings.vrlCount = 600;
    settings.seed = 17;
    settings.jitter = true;
    return settings;
}

// The message of the std::runtime_error `decode` throws, or "" if it throws none.
std::string refusal(std::span<const uint8_t> blob, const RenderSettings& settings) {
    try {
        (void)rpc::decodeJobLights(blob, settings);
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "";
}

struct Case {
    const char* name;
    RenderSettings settings;
    const char* magic;  // the blob's first bytes
};

std::vector<Case> cases() {
    std::vector<Case> all;
    all.push_back({"vrl", settingsFor(RenderMethod::Vrl), "VRLLIGHT"});
    RenderSettings plain = settingsFor(RenderMethod::Vrl);
    plain.surfaceVplLimit = 0;
    all.push_back({"vrl without surface VPLs", plain, "VRLSET"});
    all.push_back({"vrl-lightcuts", settingsFor(RenderMethod::VrlLightcuts), "VRLLIGHT"});
    RenderSettings single = settingsFor(RenderMethod::VrlLightcuts);
    single.transports = TransportSelection::parse("single");
    all.push_back({"vrl-lightcuts, part (b) alone", single, "VRLLIGHT"});
    RenderSettings tree = settingsFor(RenderMethod::VrlLightcuts);
    tree.surfaceVplLimit = 0;
    all.push_back({"vrl-lightcuts without surface VPLs", tree, "VRLTREE"});
    all.push_back({"vrl-stochastic", settingsFor(RenderMethod::VrlStochastic), "VRLTREE"});
    RenderSettings sets = settingsFor(RenderMethod::VrlStochastic);
    sets.vrlSets = 3;
    all.push_back({"vrl-stochastic, 3 VRL sets", sets, "VRLTREES"});
    all.push_back({"vpl", settingsFor(RenderMethod::Vpl), "VRLSET"});
    all.push_back({"vpl-lightcuts", settingsFor(RenderMethod::VplLightcuts), "VRLTREE"});
    return all;
}

TEST(JobLightsBlob, RoundTripsEveryKindBitForBit) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.name);
        const RenderLights lights = prepareLights(*scene, c.settings);
        const std::vector<uint8_t> blob = rpc::encodeJobLights(lights, c.settings);
        ASSERT_GE(blob.size(), std::string(c.magic).size());
        EXPECT_EQ(std::string(blob.begin(), blob.begin() + std::string(c.magic).size()), c.magic);
        const RenderLights decoded = rpc::decodeJobLights(blob, c.settings);
        EXPECT_EQ(rpc::encodeJobLights(decoded, c.settings), blob);
        EXPECT_EQ(decoded.vrls.vrls.size(), lights.vrls.vrls.size());
        EXPECT_EQ(decoded.tree.root() >= 0, lights.tree.root() >= 0);
        EXPECT_EQ(decoded.tree.vrls().size(), lights.tree.vrls().size());
        EXPECT_EQ(decoded.moreTrees.size(), lights.moreTrees.size());
        EXPECT_EQ(decoded.surfaceVpls.vpls.size(), lights.surfaceVpls.vpls.size());
        EXPECT_EQ(decoded.surfaceVpls.tree.vrls().size(), lights.surfaceVpls.tree.vrls().size());
        EXPECT_GT(lights.vrls.vrls.size() + lights.tree.vrls().size() + lights.surfaceVpls.vpls.size(), 0u)
            << "the case ships no lights";

        // A worker's tile equals the coordinator's (and an embedded render's) bit for bit.
        RenderSettings shading = c.settings;
        shading.samplesPerPixel = 2;
        const TileRect tile{3, 2, 11, 7};
        const TileSums here = TileShader(*scene, shading, lights).shadeTile(tile, 0, 2);
        const TileSums there = TileShader(*scene, shading, decoded).shadeTile(tile, 0, 2);
        ASSERT_EQ(here.sums.layers.size(), there.sums.layers.size());
        for (size_t l = 0; l < here.sums.layers.size(); ++l)
            EXPECT_TRUE(test::bitIdentical(here.sums.layers[l], there.sums.layers[l])) << "layer " << l;
        EXPECT_EQ(here.sums.boundedEstimates, there.sums.boundedEstimates);
    }
}

TEST(JobLightsBlob, APathJobShipsNothing) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    const RenderSettings settings = settingsFor(RenderMethod::Path);
    EXPECT_TRUE(rpc::encodeJobLights(prepareLights(*scene, settings), settings).empty());
}

TEST(JobLightsBlob, ABlobThatDoesNotFitTheSettingsIsRefused) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    RenderSettings sets = settingsFor(RenderMethod::VrlStochastic);
    sets.vrlSets = 3;
    const std::vector<uint8_t> threeSets = rpc::encodeJobLights(prepareLights(*scene, sets), sets);
    sets.vrlSets = 2;
    EXPECT_EQ(refusal(threeSets, sets), "the job's lights hold 3 VRL sets, but its spec asks for 2");

    const RenderSettings lightcuts = settingsFor(RenderMethod::VrlLightcuts);
    const RenderLights lights = prepareLights(*scene, lightcuts);
    const std::vector<uint8_t> tree = serializeLightTree(lights.tree);
    EXPECT_EQ(refusal(serializeJobLights(tree, {}), lightcuts),
              "the job's lights lack the surface VPLs its transports need");
    EXPECT_NE(refusal(tree, lightcuts).find("not a job lights blob"), std::string::npos) << refusal(tree, lightcuts);

    std::vector<uint8_t> corrupt = rpc::encodeJobLights(lights, lightcuts);
    corrupt[corrupt.size() / 2] ^= 1;
    EXPECT_NE(refusal(corrupt, lightcuts).find("checksum"), std::string::npos) << refusal(corrupt, lightcuts);

    RenderSettings plain = lightcuts;
    plain.method = RenderMethod::Vrl;
    plain.surfaceVplLimit = 0;
    EXPECT_NE(refusal(tree, plain), "") << "a tree read as a VRL set";
}

}  // namespace
}  // namespace vrl
