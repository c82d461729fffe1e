#include "render/renderer.h"

#include "render/core/timing.h"
#include "render/integrators/path_tracer.h"
#include "render/integrators/transport_integrator.h"
#include "render/vrl/light_tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>

namespace vrl {

namespace {

// Per-pixel cut counters: part (d)'s (the paper's Table 1), then part (c)'s.
constexpr const char* kCutLayerNames[3] = {"eval", "inter", "cut"};
constexpr const char* kSurfaceCutLayerNames[3] = {"medium-surface-eval", "medium-surface-inter", "medium-surface-cut"};
// vrl-stochastic: VRL estimates, node importances computed and cut size, per pixel and camera sample.
constexpr const char* kStochasticLayerNames[3] = {"eval", "importance", "cut"};
constexpr const char* kSurfaceStochasticLayerNames[3] = {"medium-surface-eval", "medium-surface-importance",
                                                         "medium-surface-cut"};

// The ray of image pixel (x, y): through its film pixel, so a crop shades what the full film would.
Ray cameraRay(const PerspectiveCamera& camera, const RenderSettings& settings, int x, int y, Rng& rng) {
    const float jx = settings.jitter ? rng.next() : 0.5f;
    const float jy = settings.jitter ? rng.next() : 0.5f;
    return camera.generateRay(float(x + camera.cropX0()) + jx, float(y + camera.cropY0()) + jy);
}

bool isVrlMethod(const RenderSettings& settings) { return usesVirtualLights(settings.method); }

// Part (c) comes from the VRLs (the VPL methods path-trace it).
bool vrlLitSurfaces(const RenderSettings& settings) {
    return isVrlMethod(settings) && !usesVpls(settings.method) && settings.transports.has(TransportPart::MediumSurface);
}

// The virtual lights are traced: part (d), or part (c) by VRLs, is selected.
bool needsLights(const RenderSettings& settings) {
    return isVrlMethod(settings) && (settings.transports.has(TransportPart::Multiple) || vrlLitSurfaces(settings));
}

}  // namespace

std::string_view methodName(RenderMethod method) {
    switch (method) {
        case RenderMethod::Path: return "path";
        case RenderMethod::Vrl: return "vrl";
        case RenderMethod::VrlLightcuts: return "vrl-lightcuts";
        case RenderMethod::VrlStochastic: return "vrl-stochastic";
        case RenderMethod::Vpl: return "vpl";
        case RenderMethod::VplLightcuts: return "vpl-lightcuts";
    }
    throw std::invalid_argument("unknown RenderMethod " + std::to_string(int(method)));
}

std::vector<std::string> renderMethodNames() {
    std::vector<std::string> names;
    for (RenderMethod m : kRenderMethods) names.emplace_back(methodName(m));
    return names;
}

RenderMethod parseRenderMethod(std::string_view name) {
    for (RenderMethod m : kRenderMethods)
        if (methodName(m) == name) return m;
    std::string valid;
    for (RenderMethod m : kRenderMethods) valid += (valid.empty() ? "" : ", ") + std::string(methodName(m));
    throw std::invalid_argument("unknown method '" + std::string(name.substr(0, 64)) + "' (valid: " + valid + ")");
}

void validateRenderSettings(const RenderSettings& settings) {
    if (settings.samplesPerPixel < 1) throw std::invalid_argument("samples per pixel must be at least 1");
    if (settings.vrlSamples < 1) throw std::invalid_argument("samples per VRL must be at least 1");
    if (!(settings.cut.errorThreshold >= 0.0f)) throw std::invalid_argument("the error threshold must be >= 0");
    if (settings.vplDistanceSamples < 1) throw std::invalid_argument("VPL distance samples must be at least 1");
    if (settings.cut.stochasticCutSize < 1 || settings.cut.stochasticCutSize > (1u << 20))
        throw std::invalid_argument("the stochastic cut size must be in [1, 1048576], not " +
                                    std::to_string(settings.cut.stochasticCutSize));
}

RenderLights prepareLights(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress,
                           RenderStatistics* statistics) {
    validateRenderSettings(settings);
    RenderLights lights;
    if (!needsLights(settings)) return lights;
    RenderStatistics local;
    RenderStatistics& stats = statistics ? *statistics : local;
    LightTracingSettings tracing;
    tracing.lightPaths = settings.lightPaths;
    tracing.targetVrls = settings.vrlCount;
    tracing.maxDepth = settings.maxDepth;
    tracing.seed = settings.seed ^ 0x5bd1e995ULL;  // a stream family apart from the camera's
    const bool points = usesVpls(settings.method);
    if (points) tracing.deposit = LightDeposit::Points;
    lights.vrls = traceVrls(scene, tracing, [&](double f) {
        if (progress) progress("light tracing", f);
    });
    stats.vrlCount = lights.vrls.vrls.size();
    stats.lightPaths = lights.vrls.lightPaths;
    stats.vrlBytes = lights.vrls.memoryBytes();
    stats.tracingSeconds = lights.vrls.tracingSeconds;
    if (usesLightTree(settings.method) && !lights.vrls.vrls.empty()) {
        if (progress) progress("building the light tree", 0.0);
        const auto treeStart = std::chrono::steady_clock::now();
        // The tree takes the VRLs over: shading reads them from it.
        lights.tree = LightTree::build(std::move(lights.vrls.vrls),
                                       LightTreeSettings{settings.partitionSize, settings.seed, points});
        lights.vrls.vrls = {};
        stats.treeSeconds = secondsSince(treeStart);
        stats.treeBytes = lights.tree.memoryBytes();
        if (progress) progress("building the light tree", 1.0);
    }
    return lights;
}

uint64_t estimateLightMemoryBytes(const RenderSettings& settings) {
    if (!needsLights(settings) || settings.lightPaths > 0) return 0;
    // The light tracer's vector may double while it is filled (2 lights per
    // light); a tree takes the lights over and adds 2 nodes per light plus its
    // build scratch (packed boxes, freed once it is built).
    double perLight = 2.0 * sizeof(Vrl);
    if (usesLightTree(settings.method)) perLight += 2.0 * sizeof(LightTreeNode) + double(LightTree::buildScratchBytesPerVrl());
    const double bytes = perLight * double(settings.vrlCount);
    return bytes >= 1.8e19 ? ~uint64_t(0) : uint64_t(bytes);
}

std::vector<TileRect> imageTiles(int width, int height, int tileSize) {
    const int tile = std::max(1, tileSize);
    std::vector<TileRect> tiles;
    for (int y0 = 0; y0 < height; y0 += tile)
        for (int x0 = 0; x0 < width; x0 += tile)
            tiles.push_back({x0, y0, std::min(width, x0 + tile), std::min(height, y0 + tile)});
    return tiles;
}

std::vector<std::string> renderLayerNames(const RenderSettings& settings) {
    validateRenderSettings(settings);
    std::vector<std::string> names;
    if (!isVrlMethod(settings)) return names;
    for (size_t p = 0; p < kTransportPartNames.size(); ++p)
        if (settings.transports.enabled[p]) names.emplace_back(kTransportPartNames[p]);
    if (usesLightTree(settings.method)) {
        const bool stochastic = settings.method == RenderMethod::VrlStochastic;
        for (const char* name : stochastic ? kStochasticLayerNames : kCutLayerNames) names.emplace_back(name);
        if (vrlLitSurfaces(settings))
            for (const char* name : stochastic ? kSurfaceStochasticLayerNames : kSurfaceCutLayerNames)
                names.emplace_back(name);
    }
    return names;
}

namespace {

// Lights that arrive from elsewhere (a deserialised blob) must belong to this
// scene: every medium index in range, or shading would index out of bounds.
void checkLightsMatchScene(const Scene& scene, const RenderLights& lights) {
    const size_t media = scene.media().size();
    const auto check = [&](const std::vector<Vrl>& vrls) {
        for (size_t k = 0; k < vrls.size(); ++k)
            if (vrls[k].medium < 0 || size_t(vrls[k].medium) >= media)
                throw std::invalid_argument("light " + std::to_string(k) + " lies in medium " +
                                            std::to_string(vrls[k].medium) + " but the scene has " +
                                            std::to_string(media) + " media: the lights do not belong to this scene");
    };
    check(lights.vrls.vrls);
    check(lights.tree.vrls());
    for (const LightTreeNode& node : lights.tree.nodes())
        if (node.medium < -1 || node.medium >= int32_t(media))
            throw std::invalid_argument("a light-tree node names medium " + std::to_string(node.medium) +
                                        " but the scene has " + std::to_string(media) + " media");
}

}  // namespace

TileShader::TileShader(const Scene& scene, const RenderSettings& settings, const RenderLights& lights)
    : scene_(scene), settings_(settings), layerNames_(renderLayerNames(settings)) {
    checkLightsMatchScene(scene, lights);
    if (isVrlMethod(settings)) {
        const bool lightcuts = usesLightTree(settings.method);
        TransportIntegratorSettings integratorSettings{settings.transports, settings.maxDepth, settings.vrlSamples,
                                                 settings.cut};
        integratorSettings.vpls = usesVpls(settings.method);
        integratorSettings.vplDistanceSamples = settings.vplDistanceSamples;
        integratorSettings.stochastic = settings.method == RenderMethod::VrlStochastic;
        integrator_ = std::make_unique<TransportIntegrator>(scene, lights.vrls, integratorSettings,
                                                      lightcuts && lights.tree.root() >= 0 ? &lights.tree : nullptr);
    } else {
        tracer_ = std::make_unique<VolumetricPathTracer>(scene, PathTracerSettings{settings.maxDepth});
    }
}

TileShader::~TileShader() = default;

TileImages TileShader::renderTile(const TileRect& tile, const RenderStop& stop) const {
    const PerspectiveCamera& camera = scene_.camera();
    if (tile.x0 < 0 || tile.y0 < 0 || tile.x1 > camera.width() || tile.y1 > camera.height() || tile.x0 >= tile.x1 ||
        tile.y0 >= tile.y1)
        throw std::invalid_argument("tile outside the image");
    const int w = tile.width(), h = tile.height();
    TileImages out;
    out.layers.assign(1 + layerNames_.size(), Image(w, h));
    const float spp = float(settings_.samplesPerPixel);
    for (int y = tile.y0; y < tile.y1; ++y) {
        if (stop()) {
            out.interrupted = true;
            out.rowsDone = y - tile.y0;
            return out;
        }
        for (int x = tile.x0; x < tile.x1; ++x) {
            Rng rng(settings_.seed, camera.filmPixelIndex(x, y));
            const int tx = x - tile.x0, ty = y - tile.y0;
            if (tracer_) {
                Rgb sum(0.0f);
                for (int s = 0; s < settings_.samplesPerPixel; ++s)
                    sum += tracer_->radiance(cameraRay(camera, settings_, x, y, rng), scene_.cameraMedium(), rng);
                out.layers[0].at(tx, ty) = sum / spp;
                continue;
            }
            std::array<Rgb, 4> parts{Rgb(0.0f), Rgb(0.0f), Rgb(0.0f), Rgb(0.0f)};
            CutStatistics cut, surfaceCut;
            const bool perSample = integrator_->virtualLightsPerSample();
            const auto addVirtualLights = [&](const TransportIntegrator::VirtualLightParts& lit) {
                if (integrator_->vrlLitSurfaces()) parts[size_t(TransportPart::MediumSurface)] += lit.mediumSurface;
                parts[size_t(TransportPart::Multiple)] += lit.multiple;
            };
            for (int s = 0; s < settings_.samplesPerPixel; ++s) {
                const Ray ray = cameraRay(camera, settings_, x, y, rng);
                const auto sample = integrator_->samplePathParts(ray, rng);
                for (size_t p = 0; p < 4; ++p) parts[p] += sample[p];
                // Stochastic cuts: (c) and (d) per camera sample, along the same ray.
                if (perSample) addVirtualLights(integrator_->virtualLightParts(ray, rng, &cut, &surfaceCut));
            }
            for (size_t p = 0; p < 4; ++p) parts[p] /= spp;
            if (!perSample) {
                // (c) and (d) by VRLs once per pixel: their cost is per VRL, not per camera sample.
                const float pathLuminance = std::max(0.0f, luminance(parts[0] + parts[1] + parts[2]));
                addVirtualLights(integrator_->virtualLightParts(cameraRay(camera, settings_, x, y, rng), rng, &cut,
                                                                &surfaceCut, pathLuminance));
            }
            // Counters per pixel and camera sample when (c), (d) are sampled per camera sample.
            const float counterScale = perSample ? 1.0f / spp : 1.0f;
            Rgb sum(0.0f);
            size_t layer = 1;
            for (size_t p = 0; p < parts.size(); ++p) {
                if (!settings_.transports.enabled[p]) continue;
                sum += parts[p];
                out.layers[layer++].at(tx, ty) = parts[p];
            }
            out.layers[0].at(tx, ty) = sum;
            if (usesLightTree(settings_.method)) {
                out.layers[layer++].at(tx, ty) = Rgb(float(cut.evaluated) * counterScale);
                out.layers[layer++].at(tx, ty) =
                    Rgb(float(perSample ? cut.importanceEvaluations : cut.intersected) * counterScale);
                out.layers[layer++].at(tx, ty) = Rgb(float(cut.cutSize) * counterScale);
                if (layer < out.layers.size()) {
                    out.layers[layer++].at(tx, ty) = Rgb(float(surfaceCut.evaluated) * counterScale);
                    out.layers[layer++].at(tx, ty) =
                        Rgb(float(perSample ? surfaceCut.importanceEvaluations : surfaceCut.intersected) * counterScale);
                    out.layers[layer++].at(tx, ty) = Rgb(float(surfaceCut.cutSize) * counterScale);
                }
                out.boundExceeded += cut.boundExceeded + surfaceCut.boundExceeded;
                out.boundedEstimates += cut.boundedEstimates + surfaceCut.boundedEstimates;
            }
        }
    }
    return out;
}

ImageSet assembleImageSet(std::vector<Image> layers, const std::vector<std::string>& layerNames,
                          RenderStatistics* statistics) {
    if (layers.size() != layerNames.size() + 1) throw std::invalid_argument("assembleImageSet: layer count mismatch");
    ImageSet result;
    result.image = std::move(layers[0]);
    for (size_t l = 0; l < layerNames.size(); ++l) {
        const std::string& name = layerNames[l];
        if (statistics) {
            double sum = 0.0;
            for (const auto& p : layers[l + 1].pixels()) sum += p.x;
            const double mean = layers[l + 1].pixelCount() ? sum / double(layers[l + 1].pixelCount()) : 0.0;
            if (name == kCutLayerNames[0]) statistics->meanEvaluated = mean;
            if (name == kCutLayerNames[1]) statistics->meanIntersected = mean;
            if (name == kCutLayerNames[2]) statistics->meanCutSize = mean;
            if (name == kSurfaceCutLayerNames[0]) statistics->surfaceMeanEvaluated = mean;
            if (name == kSurfaceCutLayerNames[1]) statistics->surfaceMeanIntersected = mean;
            if (name == kSurfaceCutLayerNames[2]) statistics->surfaceMeanCutSize = mean;
            if (name == kStochasticLayerNames[1]) statistics->meanImportance = mean;
            if (name == kSurfaceStochasticLayerNames[1]) statistics->surfaceMeanImportance = mean;
        }
        result.layers.emplace_back(name, std::move(layers[l + 1]));
        for (const char* counter : kCutLayerNames)
            if (name == counter) result.singleChannelLayers.insert(name);
        for (const char* counter : kSurfaceCutLayerNames)
            if (name == counter) result.singleChannelLayers.insert(name);
        for (const char* counter : kStochasticLayerNames)
            if (name == counter) result.singleChannelLayers.insert(name);
        for (const char* counter : kSurfaceStochasticLayerNames)
            if (name == counter) result.singleChannelLayers.insert(name);
    }
    return result;
}

ImageSet render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress,
                RenderStatistics* statistics, const RenderStop& stop, RenderCoverage* coverage) {
    validateRenderSettings(settings);
    RenderStatistics stats;
    const auto stopRequested = [&] { return stop(); };
    // Light tracing runs in TBB tasks; an exception from its progress callback
    // cancels them and reaches the caller.
    const ProgressCallback preparing = [&](const char* phase, double fraction) {
        if (stopRequested()) throw RenderInterrupted();
        if (progress) progress(phase, fraction);
    };
    const RenderLights lights = prepareLights(scene, settings, preparing, &stats);
    if (stopRequested()) throw RenderInterrupted();
    const auto start = std::chrono::steady_clock::now();
    const TileShader shader(scene, settings, lights);
    const int width = scene.camera().width(), height = scene.camera().height();
    std::vector<Image> layers(1 + shader.layerNames().size(), Image(width, height));
    const std::vector<TileRect> tiles = imageTiles(width, height, settings.tileSize);
    std::atomic<uint64_t> boundExceeded{0}, boundedEstimates{0};
    std::atomic<long long> pixelsDone{0};
    std::atomic<int> tilesDone{0};
    std::vector<int> tileRows(tiles.size(), 0);  // rows shaded per tile
    const double totalPixels = double(width) * height;
    if (progress) progress("rendering", 0.0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles.size(), 1), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t t = range.begin(); t < range.end(); ++t) {
            if (stopRequested()) return;
            const TileRect& tile = tiles[t];
            TileImages images = shader.renderTile(tile, stop);
            const int rows = images.interrupted ? images.rowsDone : tile.height();
            tileRows[t] = rows;
            for (size_t l = 0; l < layers.size(); ++l)
                for (int y = 0; y < rows; ++y)
                    std::copy_n(&images.layers[l].at(0, y), tile.width(), &layers[l].at(tile.x0, tile.y0 + y));
            if (images.interrupted) return;
            ++tilesDone;
            boundExceeded += images.boundExceeded;
            boundedEstimates += images.boundedEstimates;
            const long long count = static_cast<long long>(tile.width()) * tile.height();
            const long long done = pixelsDone.fetch_add(count) + count;
            if (progress) progress("rendering", double(done) / totalPixels);
        }
    });
    if (coverage) {
        coverage->tilesTotal = int(tiles.size());
        coverage->tilesDone = tilesDone.load();
        coverage->rowsDone = 0;
        coverage->covered.assign(size_t(width) * height, 0);
        for (size_t t = 0; t < tiles.size(); ++t) {
            coverage->rowsDone += tileRows[t];
            for (int y = tiles[t].y0; y < tiles[t].y0 + tileRows[t]; ++y)
                std::fill_n(&coverage->covered[size_t(y) * width + tiles[t].x0], tiles[t].width(), uint8_t(1));
        }
    }
    ImageSet result = assembleImageSet(std::move(layers), shader.layerNames(), &stats);
    stats.boundExceeded = boundExceeded.load();
    stats.boundedEstimates = boundedEstimates.load();
    stats.seconds = secondsSince(start);
    stats.cameraSamples = uint64_t(width) * height * settings.samplesPerPixel;
    if (statistics) *statistics = stats;
    return result;
}

}  // namespace vrl
