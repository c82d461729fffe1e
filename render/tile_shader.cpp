#include "render/tile_shader.h"

#include "render/integrators/path_tracer.h"
#include "render/integrators/pixel_footprint.h"
#include "render/integrators/transport_integrator.h"
#include "render/sample_passes.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace vrl {

namespace {

// Point (sx, sy) of a side x side grid over image pixel (x, y): jittered within its stratum,
// or its centre; through the film pixel, so a crop shades what the full film would.
Ray stratifiedCameraRay(const PerspectiveCamera& camera, const RenderSettings& settings, int x, int y, int sx, int sy,
                        int side, Rng& rng) {
    const float jx = settings.jitter ? rng.next() : 0.5f;
    const float jy = settings.jitter ? rng.next() : 0.5f;
    const float inverse = 1.0f / float(side);
    return camera.generateRay(float(x + camera.cropX0()) + (float(sx) + jx) * inverse,
                              float(y + camera.cropY0()) + (float(sy) + jy) * inverse);
}

// The ray of image pixel (x, y): the grid of side 1 ((0 + j) x 1 = j, the same bits as j).
Ray cameraRay(const PerspectiveCamera& camera, const RenderSettings& settings, int x, int y, Rng& rng) {
    return stratifiedCameraRay(camera, settings, x, y, 0, 0, 1, rng);
}

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
    const auto checkTree = [&](const LightTree& tree) {
        check(tree.vrls());
        for (const LightTreeNode& node : tree.nodes())
            if (node.medium < -1 || node.medium >= int32_t(media))
                throw std::invalid_argument("a light-tree node names medium " + std::to_string(node.medium) +
                                            " but the scene has " + std::to_string(media) + " media");
    };
    checkTree(lights.tree);
    for (const LightTree& tree : lights.moreTrees) checkTree(tree);
    const SurfaceVplLights& surface = lights.surfaceVpls;
    for (size_t k = 0; k < surface.vpls.size(); ++k) {
        const SurfaceVpl& vpl = surface.vpls[k];
        if (vpl.shape >= scene.shapes().size() || vpl.medium < -1 || vpl.medium >= int32_t(media))
            throw std::invalid_argument("surface VPL " + std::to_string(k) + " lies on shape " +
                                        std::to_string(vpl.shape) + " in medium " + std::to_string(vpl.medium) +
                                        " but the scene has " + std::to_string(scene.shapes().size()) + " shapes and " +
                                        std::to_string(media) + " media: the lights do not belong to this scene");
    }
    if (!surface.tree.empty() && surface.tree.vrls().size() != surface.vpls.size())
        throw std::invalid_argument("the surface VPL tree holds " + std::to_string(surface.tree.vrls().size()) +
                                    " lights but the list beside it " + std::to_string(surface.vpls.size()) +
                                    ": the lights are corrupt");
}

// One pixel's values, one per layer (image first), summed or set by shadeTile.
using PixelValues = std::vector<Rgb>;

// A cut's three counters into layers [first, first + 3): set (once per pixel) or
// added (per camera sample: a stochastic cut, whose middle counter is the node
// importances computed rather than #Inter).
void putCounters(PixelValues& values, int first, const CutStatistics& cut, bool perSample) {
    if (first < 0) return;
    const uint32_t counts[3] = {cut.evaluated, perSample ? cut.importanceEvaluations : cut.intersected, cut.cutSize};
    for (int i = 0; i < 3; ++i) {
        Rgb& v = values[size_t(first + i)];
        v = perSample ? v + Rgb(float(counts[i])) : Rgb(float(counts[i]));
    }
}

}  // namespace

TileShader::TileShader(const Scene& scene, const RenderSettings& settings, const RenderLights& lights)
    : scene_(scene), settings_(settings), layerNames_(renderLayerNames(settings)) {
    checkLightsMatchScene(scene, lights);
    const MethodTraits& method = methodTraits(settings.method);
    if (method.lights != VirtualLights::None) {
        TransportIntegratorSettings integratorSettings;
        integratorSettings.transports = settings.transports;
        integratorSettings.maxDepth = settings.maxDepth;
        integratorSettings.vrlSamples = settings.vrlSamples;
        integratorSettings.cut = settings.cut;
        integratorSettings.estimators = method.estimators;
        integratorSettings.vplDistanceSamples = settings.vplDistanceSamples;
        // (c) once per pixel over interleaved points of the pixel; at pixel centres, the centre's alone.
        integratorSettings.surfacePointsSide = settings.jitter ? kInterleavedPointsSide : 1;
        integrator_ = std::make_unique<TransportIntegrator>(
            scene, lights.vrls, integratorSettings, method.lightTree && lights.tree.root() >= 0 ? &lights.tree : nullptr,
            usesSurfaceVpls(settings) ? &lights.surfaceVpls : nullptr);
        lightsPerSample_ = method.estimators.perSample();
        // Sets 1 ... P-1 (vrl-stochastic): each set's tree, or none when its light tracing found no VRL.
        if (lights.moreTrees.size() + 1 != size_t(settings.vrlSets) && (lights.tree.root() >= 0 || !lights.moreTrees.empty()))
            throw std::invalid_argument("the lights hold " + std::to_string(1 + lights.moreTrees.size()) +
                                        " VRL sets but the render asks for " + std::to_string(settings.vrlSets));
        for (const LightTree& tree : lights.moreTrees)
            moreIntegrators_.push_back(std::make_unique<TransportIntegrator>(
                scene, lights.vrls, integratorSettings, tree.root() >= 0 ? &tree : nullptr));
    } else {
        tracer_ = std::make_unique<VolumetricPathTracer>(scene, PathTracerSettings{settings.maxDepth});
    }
    // Once per pixel: the virtual-light parts (c) (when by VRLs) and (d), and the cut counters.
    layerPerPixel_.assign(1 + layerNames_.size(), 0);
    for (size_t l = 0; l < layerNames_.size(); ++l) {
        const std::string& name = layerNames_[l];
        const int layer = int(l + 1);
        const auto part = std::find(kTransportPartNames.begin(), kTransportPartNames.end(), name);
        if (part != kTransportPartNames.end()) layout_.part[part - kTransportPartNames.begin()] = layer;
        if (name == kSurfaceVplLayerName) layout_.singleVpl = layer;
        if (name == kCutLayerNames[0]) layout_.counters = layer;  // the stochastic cut's first is "eval" too
        if (name == kSurfaceCutLayerNames[0]) layout_.surfaceCounters = layer;
        if (name == kSurfaceVplCutLayerNames[0]) layout_.surfaceVplCounters = layer;
        if (integrator_ && !lightsPerSample_) {
            const bool virtualLightPart = name == kTransportPartNames[size_t(TransportPart::Multiple)] ||
                                          (name == kTransportPartNames[size_t(TransportPart::MediumSurface)] &&
                                           integrator_->vrlLitSurfaces());
            layerPerPixel_[l + 1] = part == kTransportPartNames.end() || virtualLightPart;
        }
    }
}

TileShader::~TileShader() = default;

TileImages TileShader::renderTile(const TileRect& tile, const RenderStop& stop) const {
    TileSums shaded = shadeTile(tile, 0, passesFor(settings_.samplesPerPixel), stop);
    TileImages out;
    out.layers = resolveSamples(shaded.sums, layerNames_, settings_.samplesPerPixel);
    out.boundExceeded = shaded.sums.boundExceeded;
    out.boundedEstimates = shaded.sums.boundedEstimates;
    out.interrupted = shaded.interrupted;
    out.rowsDone = shaded.rowsDone;
    return out;
}

TileSums TileShader::shadeTile(const TileRect& tile, int firstPass, int passCount, const RenderStop& stop) const {
    const PerspectiveCamera& camera = scene_.camera();
    if (tile.x0 < 0 || tile.y0 < 0 || tile.x1 > camera.width() || tile.y1 > camera.height() || tile.x0 >= tile.x1 ||
        tile.y0 >= tile.y1)
        throw std::invalid_argument("tile outside the image");
    if (firstPass < 0 || passCount < 1 || firstPass > kMaxPasses || (firstPass > 0 && passCount != 1))
        throw std::invalid_argument("shadeTile: passes [" + std::to_string(firstPass) + ", +" +
                                    std::to_string(passCount) + ") must start at pass 0 or be a single pass");
    const size_t layerCount = 1 + layerNames_.size();
    TileSums out;
    out.sums = SampleSums::zeros(tile.width(), tile.height(), layerPerPixel_);
    PixelValues total(layerCount), pass(layerCount);
    for (int y = tile.y0; y < tile.y1; ++y) {
        if (stop()) {
            out.interrupted = true;
            out.rowsDone = y - tile.y0;
            return out;
        }
        for (int x = tile.x0; x < tile.x1; ++x) {
            const uint64_t pixel = camera.filmPixelIndex(x, y);
            std::fill(total.begin(), total.end(), Rgb(0.0f));
            float firstSampleLuminance = 0.0f;  // of sample 0's path-sampled parts, for (c)'s cut
            for (int p = firstPass; p < firstPass + passCount; ++p) {
                const SamplePass samples = samplePass(p, settings_.samplesPerPixel);
                if (samples.count == 0) break;
                std::fill(pass.begin(), pass.end(), Rgb(0.0f));
                for (int s = samples.first; s < samples.first + samples.count; ++s) {
                    Rng rng(settings_.seed, Rng::combine(pixel, uint64_t(s)));
                    const Ray ray = cameraRay(camera, settings_, x, y, rng);
                    if (tracer_) {
                        pass[0] += tracer_->radiance(ray, scene_.cameraMedium(), rng);
                        continue;
                    }
                    std::array<Rgb, 4> parts = integrator_->samplePathParts(ray, rng);
                    const float pathLuminance = std::max(0.0f, luminance(parts[0] + parts[1] + parts[2]));
                    if (s == 0) firstSampleLuminance = pathLuminance;
                    CutStatistics cut, surfaceCut;
                    if (lightsPerSample_) {
                        // Sample s draws from VRL set s mod P (set 0: integrator_).
                        const size_t set = size_t(s) % (moreIntegrators_.size() + 1);
                        const TransportIntegrator& lighting = set == 0 ? *integrator_ : *moreIntegrators_[set - 1];
                        const auto lit = lighting.virtualLightParts(ray, rng, &cut, &surfaceCut, pathLuminance);
                        if (integrator_->vrlLitSurfaces()) parts[size_t(TransportPart::MediumSurface)] = lit.mediumSurface;
                        parts[size_t(TransportPart::Multiple)] = lit.multiple;
                        out.sums.boundExceeded += cut.boundExceeded + surfaceCut.boundExceeded;
                        out.sums.boundedEstimates += cut.boundedEstimates + surfaceCut.boundedEstimates;
                    }
                    for (size_t part = 0; part < parts.size(); ++part)
                        if (layout_.part[part] >= 0) pass[size_t(layout_.part[part])] += parts[part];
                    if (lightsPerSample_) {
                        putCounters(pass, layout_.counters, cut, true);
                        putCounters(pass, layout_.surfaceCounters, surfaceCut, true);
                    }
                }
                // The canonical fold: the first pass's sums as they are, later ones added (per-sample layers only).
                for (size_t l = 0; l < layerCount; ++l)
                    if (!layerPerPixel_[l]) total[l] = p == firstPass ? pass[l] : total[l] + pass[l];
                if (p == 0 && integrator_ && !lightsPerSample_)
                    shadePixelLights(x, y, pixel, firstSampleLuminance, total, out.sums);
            }
            for (size_t l = 0; l < layerCount; ++l) out.sums.layers[l].at(x - tile.x0, y - tile.y0) = total[l];
        }
    }
    return out;
}

void TileShader::shadePixelLights(int x, int y, uint64_t pixel, float firstSampleLuminance, PixelValues& total,
                                  SampleSums& sums) const {
    // (c) and (d) once per pixel, in pass 0, from the pixel's own stream: their cost is per
    // VRL, not per camera sample. (c)'s cut measures its error against sample 0's other parts.
    // With K x K shading points, point m has its own stream and stratum; their mean is the
    // pixel's value and the counters their sum.
    const PerspectiveCamera& camera = scene_.camera();
    const int side = settings_.shadingPointsPerSide, points = side * side;
    CutStatistics cut, surfaceCut, surfaceVplCut;
    TransportIntegrator::VirtualLightParts lit;
    for (int m = 0; m < points; ++m) {
        Rng rng(settings_.seed, Rng::combine(pixel, kPixelLightsSample - uint64_t(m)));
        const Ray ray = stratifiedCameraRay(camera, settings_, x, y, m % side, m / side, side, rng);
        // The point's stratum: (c) interleaves its VRLs over 2 x 2 points of it when
        // jittered, one representative per class of coherent points, with its
        // textures averaged over its class's quarters, else takes the ray's own point
        // with its textures averaged over the stratum (pixel_footprint.h).
        const float stratum = 1.0f / float(side);
        const FilmSquare square{float(x + camera.cropX0()) + float(m % side) * stratum,
                                float(y + camera.cropY0()) + float(m / side) * stratum, stratum};
        const auto one = integrator_->virtualLightParts(ray, rng, &cut, &surfaceCut, firstSampleLuminance,
                                                        &surfaceVplCut, &square);
        if (m == 0) {
            lit = one;
            continue;
        }
        lit.mediumSurface += one.mediumSurface, lit.multiple += one.multiple, lit.singleSurface += one.singleSurface;
    }
    if (points > 1) {
        const float inverse = 1.0f / float(points);
        lit.mediumSurface *= inverse, lit.multiple *= inverse, lit.singleSurface *= inverse;
    }
    if (const int l = layout_.part[size_t(TransportPart::Multiple)]; l >= 0) total[size_t(l)] = lit.multiple;
    if (const int l = layout_.part[size_t(TransportPart::MediumSurface)]; l >= 0 && integrator_->vrlLitSurfaces())
        total[size_t(l)] = lit.mediumSurface;
    if (layout_.singleVpl >= 0) total[size_t(layout_.singleVpl)] = lit.singleSurface;
    putCounters(total, layout_.counters, cut, false);
    putCounters(total, layout_.surfaceCounters, surfaceCut, false);
    putCounters(total, layout_.surfaceVplCounters, surfaceVplCut, false);
    // Zero without a cut: plain estimators count nothing.
    sums.boundExceeded += cut.boundExceeded + surfaceCut.boundExceeded + surfaceVplCut.boundExceeded;
    sums.boundedEstimates += cut.boundedEstimates + surfaceCut.boundedEstimates + surfaceVplCut.boundedEstimates;
}

}  // namespace vrl
