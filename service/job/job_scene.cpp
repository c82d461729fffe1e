#include "service/job/job_scene.h"

#include "render/scene_io/medium_fill.h"
#include "service/common/rpc_common.h"

#include "render/description/scene_description.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "util/strings.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

namespace vrl::rpc {

namespace {
constexpr int kMaxDepth = 100000;  // as `vrl render --max-depth`

// A method with virtual lights needs some for its multiple scattering.
void checkLightCount(RenderMethod method, const v1::RenderParameters& p) {
    if (usesVirtualLights(method) && TransportSelection::parse(p.transport()).has(TransportPart::Multiple) &&
        p.vrl_count() == 0 && p.light_paths() == 0)
        throw JobSpecError("method " + std::string(methodName(method)) +
                           " needs a VRL count or a number of light paths (both are 0)");
}

// The spec's method; if it names none, the scene's <integrator> when that names
// one of ours (renderMethodNames, exactly), else kHeadlineMethod.
RenderMethod jobMethod(const v1::RenderParameters& p, const IntegratorDescription& integrator) {
    if (!p.method().empty()) return parseRenderMethod(p.method());
    for (const RenderMethod method : kRenderMethods)
        if (integrator.type == methodName(method)) return method;
    return kHeadlineMethod;
}

// The spec's crop window (of the film as resolved), or the scene's checked
// against that film; JobSpecError naming the window and the film if it does not fit.
std::optional<FilmCrop> jobCrop(const v1::RenderParameters& p, const SensorDescription& sensor) {
    const auto clamp = [](uint32_t v) { return int(std::min<uint32_t>(v, 1u << 30)); };
    if (p.has_crop()) {
        const auto& c = p.crop();
        try {
            return checkFilmCrop({clamp(c.x()), clamp(c.y()), clamp(c.width()), clamp(c.height())}, sensor.width,
                                 sensor.height);
        } catch (const std::invalid_argument& e) {
            throw JobSpecError(std::string("crop: ") + e.what());
        }
    }
    if (!sensor.crop) return std::nullopt;
    try {
        return checkFilmCrop(*sensor.crop, sensor.width, sensor.height);
    } catch (const std::invalid_argument& e) {
        throw JobSpecError(std::string("the scene's film crop does not suit the resolution asked for: ") + e.what() +
                           "; give a crop window for this resolution (vrl render --crop x,y,width,height)");
    }
}
}  // namespace

int jobTileSize(const v1::JobSpec& spec) { return spec.tile_size() == 0 ? 32 : int(spec.tile_size()); }

v1::RenderParameters defaultRenderParameters(RenderMethod method) {
    const RenderSettings d;
    v1::RenderParameters p;
    p.set_method(std::string(methodName(method)));
    p.set_samples_per_pixel(0);
    p.set_seed(d.seed);
    p.set_jitter(d.jitter);
    p.set_max_depth(-2);
    p.set_transport(d.transports.toString());
    p.set_vrl_count(d.vrlCount);
    p.set_light_paths(d.lightPaths);
    p.set_vrl_samples(d.vrlSamples);
    p.set_error(d.cut.errorThreshold);
    p.set_max_cut(d.cut.maxCutSize);
    p.set_exact_distance_below(d.cut.bound.exactDistanceBelow);
    p.set_hg_epsilon(d.cut.bound.anisotropyEpsilon);
    p.set_hg_epsilon_bound(d.cut.bound.hgBound == HgBound::Epsilon);
    p.set_glossy_heuristic_bound(d.cut.bound.glossyBound == GlossyBound::Corners);
    p.set_partition_size(d.partitionSize);
    p.set_cut_size(d.cut.stochasticCutSize);
    p.set_vrl_sets(uint32_t(d.vrlSets));
    p.set_vpl_distance_samples(uint32_t(d.vplDistanceSamples));
    p.set_surface_vpls(0);  // d.surfaceVplLimit: kAutoSurfaceVpls
    p.set_shading_points(uint32_t(d.shadingPointsPerSide));
    return p;
}

void validateJobSpec(const v1::JobSpec& spec, const ServiceLimits& limits) {
    // What a spec may hold at most (its size also bounds every lease reply that carries it).
    constexpr size_t kMaxSpecBytes = 256 << 10, kMaxDefines = 1024, kMaxNameBytes = 4096, kMaxTransportBytes = 256;
    if (spec.ByteSizeLong() > kMaxSpecBytes)
        throw JobSpecError("the job spec is " + std::to_string(spec.ByteSizeLong()) + " bytes, over the limit of " +
                           std::to_string(kMaxSpecBytes));
    if (!spec.has_parameters()) throw JobSpecError("the job has no parameters (method, samples, resolution, ...)");
    const auto& p = spec.parameters();
    std::optional<RenderMethod> method;  // empty: the scene's, known once it is parsed (resolveJob)
    try {
        if (!p.method().empty()) method = parseRenderMethod(p.method());
    } catch (const std::invalid_argument& e) {
        throw JobSpecError(e.what());
    }
    if (spec.tile_size() > limits.maxTileSize)
        throw JobSpecError("tile size " + std::to_string(spec.tile_size()) + " exceeds the limit of " +
                           std::to_string(limits.maxTileSize));
    if (p.samples_per_pixel() < 0 || p.samples_per_pixel() > limits.maxSamplesPerPixel)
        throw JobSpecError("samples per pixel must be in 0..." + std::to_string(limits.maxSamplesPerPixel) +
                           " (0: the scene's), got " + std::to_string(p.samples_per_pixel()));
    if (!(p.time_limit_seconds() >= 0.0 && p.time_limit_seconds() <= kMaxTimeLimitSeconds))
        throw JobSpecError("the time limit must be 0 (none) or a number of seconds up to " +
                           std::to_string(int64_t(kMaxTimeLimitSeconds)) + ", got " +
                           std::to_string(p.time_limit_seconds()));
    if (p.vrl_count() > limits.maxVrls || p.light_paths() > limits.maxVrls)
        throw JobSpecError("the job asks for more than " + std::to_string(limits.maxVrls) +
                           " VRLs or light paths, this coordinator's limit");
    if (p.max_depth() < -2 || p.max_depth() == 0 || p.max_depth() > kMaxDepth)
        throw JobSpecError("max depth must be -2 (the scene's), -1 (unbounded) or 1..." + std::to_string(kMaxDepth) +
                           ", got " + std::to_string(p.max_depth()));
    if (p.vrl_samples() < 1 || p.vrl_samples() > 1024)
        throw JobSpecError("VRL samples must be in 1...1024, got " + std::to_string(p.vrl_samples()));
    if (!(p.error() >= 0.0f && p.error() <= 1e6f))
        throw JobSpecError("the error threshold must be in 0...1e6, got " + std::to_string(p.error()));
    if (!(p.hg_epsilon() >= 0.0f && p.hg_epsilon() <= 1e6f))
        throw JobSpecError("hg epsilon must be in 0...1e6, got " + std::to_string(p.hg_epsilon()));
    if (p.max_cut() < 1 || p.max_cut() > (1u << 30))
        throw JobSpecError("the maximum cut size must be in 1..." + std::to_string(1u << 30) + ", got " +
                           std::to_string(p.max_cut()));
    if (p.cut_size() > (1u << 20))
        throw JobSpecError("the stochastic cut size must be in 1..." + std::to_string(1u << 20) +
                           " (0: the default), got " + std::to_string(p.cut_size()));
    if (p.vpl_distance_samples() > uint32_t(kMaxVplDistanceSamples))
        throw JobSpecError("the VPL distance samples per camera segment must be in 1..." +
                           std::to_string(kMaxVplDistanceSamples) + " (0: the default), got " +
                           std::to_string(p.vpl_distance_samples()));
    if (p.vrl_sets() > uint32_t(kMaxVrlSets))
        throw JobSpecError("the VRL sets must be in 1..." + std::to_string(kMaxVrlSets) + " (0: one), got " +
                           std::to_string(p.vrl_sets()));
    if (p.vrl_sets() > 1 && (p.vrl_count() > limits.maxVrls / p.vrl_sets() || p.light_paths() > limits.maxVrls / p.vrl_sets()))
        throw JobSpecError("the job asks for " + std::to_string(p.vrl_sets()) + " VRL sets of " +
                           std::to_string(std::max(p.vrl_count(), p.light_paths())) + " VRLs or light paths, more than " +
                           std::to_string(limits.maxVrls) + " in all, this coordinator's limit");
    if (p.surface_vpls() < -1 || (p.surface_vpls() > 0 && uint64_t(p.surface_vpls()) > limits.maxVrls))
        throw JobSpecError("the surface VPLs must be -1 (none), 0 (the default) or 1..." + std::to_string(limits.maxVrls) +
                           " (this coordinator's light limit), got " + std::to_string(p.surface_vpls()));
    if (p.shading_points() > uint32_t(kMaxShadingPointsPerSide))
        throw JobSpecError("the shading points per pixel side must be in 1..." + std::to_string(kMaxShadingPointsPerSide) +
                           " (0: one), got " + std::to_string(p.shading_points()));
    if (p.exact_distance_below() > (1u << 20))
        throw JobSpecError("exact distance below must be in 0..." + std::to_string(1u << 20) + ", got " +
                           std::to_string(p.exact_distance_below()));
    if (p.partition_size() < 2 || p.partition_size() > (1u << 30))
        throw JobSpecError("the partition size must be in 2..." + std::to_string(1u << 30) + ", got " +
                           std::to_string(p.partition_size()));
    if ((p.width() == 0) != (p.height() == 0)) throw JobSpecError("give both width and height, or neither");
    if (p.width() > 0) {
        const uint64_t pixels = uint64_t(p.width()) * p.height();
        if (p.width() > uint32_t(kMaxFilmSide) || p.height() > uint32_t(kMaxFilmSide) || pixels > limits.maxPixels)
            throw JobSpecError("resolution " + std::to_string(p.width()) + "x" + std::to_string(p.height()) +
                               " is outside the supported range (1.." + std::to_string(kMaxFilmSide) +
                               " per side, at most " + std::to_string(limits.maxPixels) + " pixels)");
        const uint64_t side = uint64_t(jobTileSize(spec));
        const uint64_t tiles = ((p.width() + side - 1) / side) * ((p.height() + side - 1) / side);
        if (tiles > limits.maxTiles)
            throw JobSpecError("the image would have " + std::to_string(tiles) + " tiles, over the limit of " +
                               std::to_string(limits.maxTiles) + "; use a larger tile size");
    }
    if (spec.defines_size() > int(kMaxDefines))
        throw JobSpecError("the job has " + std::to_string(spec.defines_size()) + " defines, over the limit of " +
                           std::to_string(kMaxDefines));
    for (const auto& [name, value] : spec.defines())
        if (name.empty() || name.size() > 256 || value.size() > 4096)
            throw JobSpecError("invalid define '" + util::abbreviate(name) + "' (" + std::to_string(name.size()) +
                               "-byte name, " + std::to_string(value.size()) +
                               "-byte value): names are 1..256 bytes, values at most 4096");
    if (spec.name().size() > kMaxNameBytes)
        throw JobSpecError("the job name is " + std::to_string(spec.name().size()) + " bytes, over the limit of " +
                           std::to_string(kMaxNameBytes));
    if (spec.medium().size() > 1024) throw JobSpecError("the fill medium description is longer than 1024 bytes");
    if (p.transport().size() > kMaxTransportBytes)
        throw JobSpecError("the transport list is " + std::to_string(p.transport().size()) +
                           " bytes, over the limit of " + std::to_string(kMaxTransportBytes));
    TransportSelection transports;
    try {
        if (!spec.medium().empty()) (void)parseFillMedium(spec.medium());
        transports = TransportSelection::parse(p.transport());
    } catch (const std::exception& e) {
        throw JobSpecError(e.what());
    }
    if (method) checkLightCount(*method, p);
}

namespace {

// resolveJob after the spec is validated and the scene parsed.
ResolvedJob resolveValidatedJob(SceneDescription parsed, const v1::JobSpec& spec, const ServiceLimits& limits) {
    const auto& p = spec.parameters();
    ResolvedJob job;
    SceneDescription& description = job.description;
    description = std::move(parsed);
    if (!spec.medium().empty()) fillWithMedium(description, parseFillMedium(spec.medium()));
    if (p.width() > 0) {
        description.sensor.width = int(std::min<uint32_t>(p.width(), 1u << 30));
        description.sensor.height = int(std::min<uint32_t>(p.height(), 1u << 30));
    }
    description.sensor.crop = jobCrop(p, description.sensor);  // relative to the film just resolved
    const auto& sensor = description.sensor;
    const uint64_t pixels = uint64_t(sensor.width) * uint64_t(sensor.height);
    if (sensor.width < 1 || sensor.height < 1 || sensor.width > kMaxFilmSide || sensor.height > kMaxFilmSide ||
        pixels > limits.maxPixels)
        throw JobSpecError("resolution " + std::to_string(sensor.width) + "x" + std::to_string(sensor.height) +
                           " is outside the supported range (1.." + std::to_string(kMaxFilmSide) +
                           " per side, at most " + std::to_string(limits.maxPixels) + " pixels)");
    RenderSettings& s = job.settings;
    s.method = jobMethod(p, description.integrator);
    checkLightCount(s.method, p);
    // With a time limit the sample count is a cap: the spec's, or none (the most a job may have).
    s.timeLimitSeconds = p.time_limit_seconds();
    s.samplesPerPixel = p.samples_per_pixel() > 0 ? p.samples_per_pixel()
                        : s.timeLimitSeconds > 0.0 ? std::min(limits.maxSamplesPerPixel, kMaxSampleCount)
                                                   : sensor.sampleCount;
    s.seed = p.seed();
    s.jitter = p.jitter();
    s.maxDepth = p.max_depth() >= -1 ? p.max_depth() : description.integrator.maxDepth;
    s.tileSize = jobTileSize(spec);
    s.transports = TransportSelection::parse(p.transport());
    s.vrlCount = p.vrl_count();
    s.lightPaths = p.light_paths();
    s.vrlSamples = p.vrl_samples();
    s.cut.errorThreshold = p.error();
    s.cut.maxCutSize = p.max_cut();
    s.cut.bound.exactDistanceBelow = p.exact_distance_below();
    s.cut.bound.anisotropyEpsilon = p.hg_epsilon();
    s.cut.bound.hgBound = p.hg_epsilon_bound() ? HgBound::Epsilon : HgBound::Cones;
    s.cut.bound.glossyBound = p.glossy_heuristic_bound() ? GlossyBound::Corners : GlossyBound::Cones;
    s.partitionSize = p.partition_size();
    if (p.cut_size() > 0) s.cut.stochasticCutSize = p.cut_size();
    s.vrlSets = p.vrl_sets() > 0 ? int(p.vrl_sets()) : 1;
    if (p.vpl_distance_samples() > 0) s.vplDistanceSamples = int(p.vpl_distance_samples());
    if (p.shading_points() > 0) s.shadingPointsPerSide = int(p.shading_points());
    s.surfaceVplLimit = p.surface_vpls() == 0 ? kAutoSurfaceVpls : p.surface_vpls() < 0 ? 0 : uint64_t(p.surface_vpls());
    try {
        validateRenderSettings(s);
    } catch (const std::invalid_argument& e) {
        throw JobSpecError(e.what());  // settings that no method takes (several VRL sets but not vrl-stochastic, ...)
    }
    return job;
}

}  // namespace

ResolvedJob resolveJob(const std::filesystem::path& sceneFile, const v1::JobSpec& spec, const ServiceLimits& limits,
                       const std::filesystem::path& confineTo) {
    validateJobSpec(spec, limits);
    ParseOptions options;
    options.defines.insert(spec.defines().begin(), spec.defines().end());
    if (!confineTo.empty()) options.confineTo = confineTo;
    return resolveValidatedJob(parseMitsubaScene(sceneFile, options), spec, limits);
}

ResolvedJob resolveParsedJob(SceneDescription description, const v1::JobSpec& spec, const ServiceLimits& limits) {
    validateJobSpec(spec, limits);
    return resolveValidatedJob(std::move(description), spec, limits);
}

JobScene loadJobScene(const std::filesystem::path& bundleDirectory, const std::filesystem::path& sceneFile,
                      const v1::JobSpec& spec, const ServiceLimits& limits) {
    ResolvedJob resolved = resolveJob(sceneFile, spec, limits, bundleDirectory);
    JobScene job;
    job.settings = resolved.settings;
    job.scene = Scene::build(resolved.description);
    job.width = job.scene->camera().width();  // the image: the crop window if there is one
    job.height = job.scene->camera().height();
    return job;
}

}  // namespace vrl::rpc
