#include "server/tile_assembly.h"

#include "render/core/timing.h"
#include "render/image/exr_io.h"
#include "render/image/partial_image.h"
#include "render/render_metadata.h"
#include "service/common/rpc_common.h"
#include "util/random_id.h"
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

// The EXR metadata record of a job's image (whole or partial).
RenderRecord recordOf(const std::string& id, const v1::JobSpec& spec, const std::map<std::string, std::string>& notes,
                      const RenderSettings& settings, const RenderStatistics& stats,
                      const std::vector<std::pair<std::string, double>>& phases, size_t workers) {
    RenderRecord record;
    record.scene = spec.name();
    record.defines.insert(spec.defines().begin(), spec.defines().end());
    record.medium = spec.medium();
    record.sceneNotes = notes;
    record.settings = settings;
    record.statistics = stats;
    // Light tracing and the tree build are in `stats` (vrl.time.lightTracing, vrl.time.treeBuild): the
    // progress phases that repeat them are not written a second time under other names.
    for (const auto& [phase, seconds] : phases)
        if (phase != kLightTracingPhase && phase != kLightTreePhase) record.phases.emplace_back(camelCase(phase), seconds);
    record.run = {{"job", id}, {"workers", int32_t(workers)}};
    return record;
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
    const TilePasses::Range passes{int(std::min<uint32_t>(result.first_pass(), kMaxPasses)),
                                   int(std::min<uint32_t>(result.pass_count(), kMaxPasses))};
    switch (job.passes.fit(tile, passes)) {
        case TilePasses::Fit::Expected: break;
        case TilePasses::Fit::Duplicate:
            merge.duplicate = true;
            merge.refusal = "duplicate: these passes of the tile were already accepted";
            return merge;
        case TilePasses::Fit::Unexpected:
            merge.refusal = "passes [" + std::to_string(result.first_pass()) + ", +" +
                            std::to_string(result.pass_count()) + ") are not what tile " + std::to_string(tile) +
                            " needs next (" + std::to_string(job.passes.nextLease(tile).first) + ", +" +
                            std::to_string(job.passes.nextLease(tile).count) + ")";
            return merge;
    }
    const size_t layerCount = 1 + job.layerNames.size();
    if (size_t(result.layers_size()) != layerCount) {
        merge.refusal = "wrong number of layers: " + std::to_string(result.layers_size()) + ", expected " +
                        std::to_string(layerCount);
        return merge;
    }
    const std::vector<uint8_t>& perPixel = job.passes.perPixel();
    for (int l = 0; l < result.layers_size(); ++l)
        if (!perPixel.empty() && result.layers(l).per_pixel() != (perPixel[size_t(l)] != 0)) {
            merge.refusal = "layer " + std::to_string(l) + " is " + (result.layers(l).per_pixel() ? "" : "not ") +
                            "per pixel, unlike the job's earlier tiles";
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
    std::vector<uint8_t> flags;
    for (int l = 0; l < result.layers_size(); ++l) flags.push_back(result.layers(l).per_pixel() ? 1 : 0);
    SampleSums sums = SampleSums::zeros(rect.width(), rect.height(), flags);
    for (int l = 0; l < result.layers_size(); ++l)
        std::memcpy(static_cast<void*>(&sums.layers[size_t(l)].at(0, 0)), result.layers(l).rgb().data(),
                    floats * sizeof(float));
    sums.boundExceeded = result.bound_exceeded();
    sums.boundedEstimates = result.bounded_estimates();
    merge.passCompleted = job.passes.accept(tile, passes, std::move(sums));
    if (job.passes.tileDone(tile) && !job.done[tile]) {
        job.done[tile] = 1;
        ++job.doneCount;
    }
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
    PartialImageInput in = partialImageInput(job);
    job.passes.clear();
    ImageSet images = assembleJobImage(in);
    try {
        writeExr(job.dir / "image.exr", images);  // atomic: a temporary sibling, then a rename
    } catch (const std::exception& e) {
        return std::string(e.what());
    }
    job.phases.emplace_back("render", secondsSince(job.renderStart));
    return std::nullopt;
}

}  // namespace vrl::server

namespace vrl::server {

PartialImageInput partialImageInput(const Job& job) {
    PartialImageInput in;
    in.sums = job.passes.imageSums(job.tiles, job.width, job.height, std::vector<uint8_t>(1 + job.layerNames.size(), 0),
                                   &in.tilesCovered);
    in.passes = job.passes.passesDone();
    in.id = job.id;
    in.spec = job.spec;
    in.width = job.width;
    in.height = job.height;
    in.tiles = job.tiles;
    in.layerNames = job.layerNames;
    in.sceneNotes = job.sceneNotes;
    in.settings = job.settings;
    in.camera = job.camera;
    in.statistics = job.renderStatistics;
    in.statistics.boundExceeded = in.sums.boundExceeded;
    in.statistics.boundedEstimates = in.sums.boundedEstimates;
    in.statistics.seconds = secondsSince(job.renderStart);
    in.phases = job.phases;
    in.workers = job.workers.size();
    return in;
}

ImageSet assembleJobImage(PartialImageInput& in) {
    // Whole passes: a complete image of their samples; none (a time-limited job's first pass cut
    // short, or an unfinished fixed job): the tiles done so far, marked partial.
    const bool whole = in.passes > 0;
    const int samples = whole ? samplesAfter(in.passes, in.settings.samplesPerPixel)
                        : in.settings.timeLimitSeconds > 0.0 ? 1 : in.settings.samplesPerPixel;
    in.statistics.samplesPerPixel = samples;
    in.statistics.passes = in.passes;
    in.statistics.cameraSamples = uint64_t(in.width) * uint64_t(in.height) * uint64_t(samples);
    ImageSet images = assembleImageSet(resolveSamples(in.sums, in.layerNames, samples), in.layerNames, &in.statistics);
    in.sums = {};
    const RenderRecord record =
        recordOf(in.id, in.spec, in.sceneNotes, in.settings, in.statistics, in.phases, in.workers);
    writeRenderMetadata(record, *in.camera, images.metadata);
    if (whole) return images;
    std::vector<uint8_t> covered(size_t(in.width) * size_t(in.height), 0);
    int tilesDone = 0;
    for (size_t t = 0; t < in.tiles.size(); ++t) {
        if (!in.tilesCovered[t]) continue;
        ++tilesDone;
        const TileRect& r = in.tiles[t];
        for (int y = r.y0; y < r.y1; ++y)
            std::fill_n(covered.begin() + ptrdiff_t(size_t(y) * size_t(in.width) + size_t(r.x0)), r.width(), uint8_t(1));
    }
    markPartial(images, covered, tilesDone, int(in.tiles.size()));
    return images;
}

std::string assemblePartialImage(PartialImageInput in, const std::filesystem::path& scratchDir) {
    ImageSet images = assembleJobImage(in);
    const std::filesystem::path file = scratchDir / ("partial-" + util::randomHex(8) + ".exr");
    writeExr(file, images);
    std::string bytes;
    try {
        bytes = rpc::readFileText(file.string());
    } catch (...) {
        std::filesystem::remove(file);
        throw;
    }
    std::filesystem::remove(file);
    return bytes;
}

}  // namespace vrl::server
