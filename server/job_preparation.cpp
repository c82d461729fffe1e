#include "server/job_preparation.h"

#include "render/core/timing.h"
#include "render/description/scene_description.h"
#include "service/common/rpc_common.h"
#include "service/job/job_lights_blob.h"
#include "service/job/job_scene.h"
#include "service/job/scene_bundle.h"
#include "util/hash.h"
#include "util/system_memory.h"

namespace vrl::server {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

Job* JobPreparation::next() const {
    Job* next = nullptr;
    for (const auto& [id, job] : store_.jobs()) {
        if (job->state != v1::JOB_STATE_QUEUED) continue;
        if (!next || job->spec.priority() > next->spec.priority() ||
            (job->spec.priority() == next->spec.priority() && job->sequence < next->sequence))
            next = job.get();
    }
    return next;
}

PreparedJob JobPreparation::prepare(const Job& job, const ProgressCallback& progress) const {
    PreparedJob prepared;
    prepared.start = Clock::now();
    auto& phases = prepared.phases;
    const std::string& sha = job.spec.bundle_sha256();
    prepared.bundle = std::make_shared<const std::string>(rpc::readFileText(store_.bundleFile(sha).string()));
    const v1::SceneBundle bundle = rpc::parseBundleBlob(*prepared.bundle, limits_);
    const fs::path directory = store_.bundleDirectory(sha);
    if (!fs::exists(directory)) rpc::extractBundle(bundle, directory);
    auto t0 = Clock::now();
    rpc::JobScene scene = rpc::loadJobScene(directory, directory / bundle.scene_path(), job.spec, limits_);
    phases.emplace_back("load scene", secondsSince(t0));
    // Work that cannot fit is refused before light tracing starts: the lights' estimated memory against this machine's.
    const uint64_t need = estimateLightMemoryBytes(scene.settings), have = util::physicalMemoryBytes();
    if (have > 0 && need > have)
        throw rpc::JobSpecError("the " + std::to_string(scene.settings.vrlCount) +
                                (usesVpls(scene.settings.method) ? " VPLs" : " VRLs") + " and their light structures need about " +
                                std::to_string(need >> 30) + " GiB, more than the coordinator's " +
                                std::to_string(have >> 30) + " GiB of memory; ask for fewer --vrls");
    prepared.sceneNotes = sceneNotes(scene.scene->description());
    RenderStatistics& statistics = prepared.statistics;
    t0 = Clock::now();
    const RenderLights lights = prepareLights(*scene.scene, scene.settings, progress, &statistics);
    if (statistics.vrlCount > 0) {
        phases.emplace_back(kLightTracingPhase, statistics.tracingSeconds);
        if (statistics.treeSeconds > 0.0) phases.emplace_back(kLightTreePhase, statistics.treeSeconds);
    }
    t0 = Clock::now();
    const std::vector<uint8_t> blob = rpc::encodeJobLights(lights, scene.settings);
    if (!blob.empty()) prepared.lights = std::make_shared<const std::string>(blob.begin(), blob.end());
    prepared.lightsSha = prepared.lights ? util::sha256Hex(*prepared.lights) : "";
    if (prepared.lights) phases.emplace_back("serialise lights", secondsSince(t0));
    prepared.layerNames = renderLayerNames(scene.settings);
    const uint64_t tileSide = uint64_t(scene.settings.tileSize);
    const uint64_t tileCount = ((uint64_t(scene.width) + tileSide - 1) / tileSide) *
                               ((uint64_t(scene.height) + tileSide - 1) / tileSide);
    if (tileCount > limits_.maxTiles)
        throw rpc::JobSpecError("the image would have " + std::to_string(tileCount) + " tiles, over the limit of " +
                                std::to_string(limits_.maxTiles) + "; use a larger tile size");
    prepared.tiles = imageTiles(scene.width, scene.height, scene.settings.tileSize);
    prepared.width = scene.width;
    prepared.height = scene.height;
    prepared.settings = scene.settings;
    prepared.camera = scene.scene->camera();

    // Accepted tiles from before a restart.
    prepared.replay = store_.readCheckpoint(job);
    return prepared;
}

void JobPreparation::install(Job& job, const PreparedJob& prepared) const {
    const auto& tiles = prepared.tiles;
    job.width = prepared.width;
    job.height = prepared.height;
    job.tiles = tiles;
    for (uint32_t t = 0; t < tiles.size(); ++t) job.tileAt[{tiles[t].x0, tiles[t].y0}] = t;
    job.layerNames = prepared.layerNames;
    job.sceneNotes = prepared.sceneNotes;
    job.settings = prepared.settings;
    job.camera = prepared.camera;
    job.done.assign(tiles.size(), 0);
    job.queued.assign(tiles.size(), 0);
    job.waiting.assign(tiles.size(), 0);
    job.rejections.assign(tiles.size(), 0);
    job.doneCount = 0;
    const bool progressive = prepared.settings.timeLimitSeconds > 0.0;
    job.passes = TilePasses(tiles.size(), passesFor(prepared.settings.samplesPerPixel), progressive);
    job.renderStatistics = prepared.statistics;
    job.assets.set_job_id(job.id);
    *job.assets.mutable_spec() = job.spec;
    job.assets.set_width(uint32_t(prepared.width));
    job.assets.set_height(uint32_t(prepared.height));
    job.assets.set_samples_per_pixel(prepared.settings.samplesPerPixel);
    job.assets.set_max_depth(prepared.settings.maxDepth);
    job.assets.set_lights_sha256(prepared.lightsSha);
    job.assets.set_lights_size(prepared.lights ? prepared.lights->size() : 0);
    job.assets.set_bundle_size(prepared.bundle->size());
    job.assets.clear_layer_names();
    for (const auto& name : prepared.layerNames) job.assets.add_layer_names(name);
    job.phases = prepared.phases;
    job.phases.emplace_back("prepare (total)", secondsSince(prepared.start));
    job.state = v1::JOB_STATE_RENDERING;
}

}  // namespace vrl::server
