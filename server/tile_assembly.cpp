#include "server/tile_assembly.h"

#include "render/core/timing.h"
#include "render/image/exr_io.h"
#include "render/render_metadata.h"
#include "util/strings.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace vrl::server {

namespace {

// A phase's display name as a metadata key: "load scene" -> "loadScene", "prepare (total)" -> "prepareTotal".
std::string camelCase(const std::string& phase) {
    std::string out;
    bool upper = false;
    for (char c : phase) {
        const bool alnum = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
        if (!alnum) {
            upper = !out.empty();
            continue;
        }
        out += upper && c >= 'a' && c <= 'z' ? char(c - 'a' + 'A') : c;
        upper = false;
    }
    return out;
}

}  // namespace

TileMerge mergeTile(Job& job, const v1::TileResult& result) {
    TileMerge merge;
    if (!(result.seconds() >= 0.0 && std::isfinite(result.seconds()))) {
        merge.refusal = "seconds must be finite and >= 0, got " + std::to_string(result.seconds());
        return merge;
    }
    const auto& t = result.tile();
    const auto at = job.tileAt.find({int(t.x0()), int(t.y0())});
    if (at == job.tileAt.end()) {
        merge.refusal = "tile (" + std::to_string(t.x0()) + ", " + std::to_string(t.y0()) +
                        ") is not a tile of this job's " + std::to_string(job.width) + "x" +
                        std::to_string(job.height) + " image";
        return merge;
    }
    const uint32_t tile = merge.tile = at->second;
    const TileRect& rect = job.tiles[tile];
    if (t.x1() != uint32_t(rect.x1) || t.y1() != uint32_t(rect.y1)) {
        merge.refusal = "tile bounds [" + std::to_string(t.x0()) + ", " + std::to_string(t.x1()) + ") x [" +
                        std::to_string(t.y0()) + ", " + std::to_string(t.y1()) + ") differ from the job's tiling";
        return merge;
    }
    if (job.done[tile]) {
        merge.duplicate = true;
        merge.refusal = "duplicate: this tile was already accepted";
        return merge;
    }
    if (size_t(result.layers_size()) != job.layers.size()) {
        merge.refusal = "wrong number of layers: " + std::to_string(result.layers_size()) + ", expected " +
                        std::to_string(job.layers.size());
        return merge;
    }
    const size_t floats = size_t(rect.width()) * rect.height() * 3;
    for (int l = 0; l < result.layers_size(); ++l) {
        const auto& layer = result.layers(l);
        const std::string& expected = l == 0 ? std::string() : job.layerNames[size_t(l - 1)];
        if (layer.name() != expected) {
            merge.refusal = "layer " + std::to_string(l) + " is '" + util::abbreviate(layer.name()) + "', expected '" +
                            expected + "'";
            return merge;
        }
        if (layer.rgb().size() != floats * sizeof(float)) {
            merge.refusal = "layer '" + layer.name() + "' has the wrong size: " + std::to_string(layer.rgb().size()) +
                            " bytes, expected " + std::to_string(floats * sizeof(float)) + " (" +
                            std::to_string(rect.width()) + "x" + std::to_string(rect.height()) + " RGB float32)";
            return merge;
        }
        for (size_t i = 0; i < floats; ++i) {
            float v;
            std::memcpy(&v, layer.rgb().data() + i * sizeof(float), sizeof v);
            if (!std::isfinite(v)) {
                merge.refusal = "layer '" + layer.name() + "' holds a non-finite value";
                return merge;
            }
        }
    }
    for (int l = 0; l < result.layers_size(); ++l) {
        const char* data = result.layers(l).rgb().data();
        for (int y = 0; y < rect.height(); ++y)
            std::memcpy(static_cast<void*>(&job.layers[size_t(l)].at(rect.x0, rect.y0 + y)),
                        data + size_t(y) * rect.width() * 3 * sizeof(float), size_t(rect.width()) * 3 * sizeof(float));
    }
    job.done[tile] = 1;
    ++job.doneCount;
    job.boundExceeded += result.bound_exceeded();
    job.boundedEstimates += result.bounded_estimates();
    return merge;
}

void creditWorker(Job& job, const std::string& workerName, const v1::TileResult& result, uint32_t tile) {
    const TileRect& rect = job.tiles[tile];
    auto& share = job.workers[workerName];
    ++share.tiles;
    share.pixels += uint64_t(rect.width()) * rect.height();
    share.seconds += std::max(0.0, result.seconds());
}

std::optional<std::string> writeJobImage(Job& job) {
    RenderStatistics stats = job.renderStatistics;
    ImageSet images = assembleImageSet(std::move(job.layers), job.layerNames, &stats);
    job.layers.clear();
    stats.boundExceeded = job.boundExceeded;
    stats.boundedEstimates = job.boundedEstimates;
    stats.seconds = secondsSince(job.renderStart);
    RenderRecord record;
    record.scene = job.spec.name();
    record.defines.insert(job.spec.defines().begin(), job.spec.defines().end());
    record.medium = job.spec.medium();
    record.sceneNotes = job.sceneNotes;
    record.settings = job.settings;
    record.statistics = stats;
    // Light tracing and the tree build are in `stats` (vrl.time.lightTracing, vrl.time.treeBuild): the
    // progress phases that repeat them are not written a second time under other names.
    for (const auto& [phase, seconds] : job.phases)
        if (phase != kLightTracingPhase && phase != kLightTreePhase) record.phases.emplace_back(camelCase(phase), seconds);
    record.run = {{"job", job.id}, {"workers", int32_t(job.workers.size())}};
    writeRenderMetadata(record, *job.camera, images.metadata);
    try {
        writeExr(job.dir / "image.exr", images);  // atomic: a temporary sibling, then a rename
    } catch (const std::exception& e) {
        return std::string(e.what());
    }
    job.phases.emplace_back("render", secondsSince(job.renderStart));
    return std::nullopt;
}

}  // namespace vrl::server
