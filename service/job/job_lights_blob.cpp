#include "service/job/job_lights_blob.h"

#include "render/lightcuts/tree/light_tree_io.h"

#include <iterator>
#include <stdexcept>
#include <string>

namespace vrl::rpc {

std::vector<uint8_t> encodeJobLights(const RenderLights& lights, const RenderSettings& settings) {
    std::vector<uint8_t> primary;  // the VRLs' blob, as a job without surface VPLs ships it alone
    if (!lights.moreTrees.empty()) {
        std::vector<const LightTree*> trees{&lights.tree};
        for (const LightTree& tree : lights.moreTrees) trees.push_back(&tree);
        primary = serializeLightTrees(trees);
    } else if (lights.tree.root() >= 0) {
        primary = serializeLightTree(lights.tree);
    } else if (!lights.vrls.vrls.empty()) {
        primary = serializeVrlSet(lights.vrls);
    }
    // Part (b)'s surface VPLs go with them in one blob, even where no VRLs are kept (--transport single).
    if (!usesSurfaceVpls(settings)) return primary;
    return serializeJobLights(primary, serializeSurfaceVpls(lights.surfaceVpls));
}

RenderLights decodeJobLights(std::span<const uint8_t> blob, const RenderSettings& settings) {
    RenderLights lights;
    std::span<const uint8_t> primary = blob;
    if (usesSurfaceVpls(settings)) {
        const JobLightsParts parts = parseJobLights(blob.data(), blob.size());
        if (parts.surfaceVpls.empty())
            throw std::runtime_error("the job's lights lack the surface VPLs its transports need");
        lights.surfaceVpls = deserializeSurfaceVpls(parts.surfaceVpls.data(), parts.surfaceVpls.size());
        primary = parts.primary;
    }
    if (primary.empty()) return lights;  // part (b) alone: no VRLs kept
    if (settings.vrlSets > 1) {          // vrl-stochastic: one tree per VRL set
        std::vector<LightTree> trees = deserializeLightTrees(primary.data(), primary.size());
        if (trees.size() != size_t(settings.vrlSets))
            throw std::runtime_error("the job's lights hold " + std::to_string(trees.size()) +
                                     " VRL sets, but its spec asks for " + std::to_string(settings.vrlSets));
        lights.tree = std::move(trees[0]);
        lights.moreTrees.assign(std::make_move_iterator(trees.begin() + 1), std::make_move_iterator(trees.end()));
    } else if (usesLightTree(settings.method)) {
        lights.tree = deserializeLightTree(primary.data(), primary.size());
    } else {
        lights.vrls = deserializeVrlSet(primary.data(), primary.size());
    }
    return lights;
}

}  // namespace vrl::rpc
