#include "client/render_options.h"

#include "render/renderer.h"
#include "render/description/scene_description.h"
#include "util/command_line.h"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <regex>
#include <stdexcept>

namespace vrl::client {

void addRenderOptions(CLI::App& cmd, RenderCommandOptions& o) {
    cmd.add_option("scene", o.scene, "Scene file (Mitsuba 0.5/0.6 XML subset)")->required();
    cmd.add_option("-o,--output", o.output, "Output OpenEXR file")->required();
    cmd.add_option("-D,--define", o.defines, "Override a scene <default>: -D name=value (repeatable)");
    cmd.add_option("--medium", o.medium,
                    "Fill a scene that has no medium with a homogeneous one, as the paper did for its benchmarks: "
                    "\"sigmaS=S,sigmaA=A[,g=G]\" (per scene unit; S and A one value or r:g:b; g: Henyey-Greenstein, "
                    "default 0 = isotropic). The camera and every light sit in it");
    cmd.add_option("--preview", o.preview,
                    "Also write a tone-mapped 8-bit PNG of the image here (automatic exposure: the 99th percentile "
                    "of luminance maps near white)");
    cmd.add_option("--method", o.method,
                    "Rendering method (default: the scene's <integrator type> if it names one of these, else "
                    "vrl-lightcuts, the headline method): path (volumetric path tracer, the reference), vrl (transport parts "
                    "(a), (b) by path sampling, VRL-lit surfaces (c) and multiple scattering (d) by plain VRLs), "
                    "vrl-lightcuts (the same, (c) and (d) by cuts through a VRL light tree), vrl-stochastic (stochastic "
                    "VRL Lightcuts: (c) and (d) by small stochastic cuts through the same tree, one VRL drawn under each "
                    "node, unbiased; --spp applies to (c) and (d) too) or vpl-lightcuts (the "
                    "paper's baseline: (d) by Lightcuts over VPLs at the light paths' medium collisions, stratified "
                    "distance samples along each camera segment (--distance-samples), (c) path-sampled; vpl: the "
                    "same with every VPL gathered, no tree). No method clamps contributions")
        ->check(CLI::IsMember(renderMethodNames()));
    cmd.add_option("--spp", o.spp,
                   "Samples per pixel (default: the scene's sampler sampleCount); with --time-limit, the most "
                   "samples per pixel to render (default: no cap but the limit)")
        ->check(CLI::Range(1, kMaxSampleCount));
    cmd.add_option("--time-limit", o.timeLimit,
                   "Render progressively for about this many seconds (after light preparation): passes of 1, 2, "
                   "4, ... samples per pixel over the whole image until the limit (or --spp) is reached; the image "
                   "holds the completed passes (2^P - 1 samples per pixel, bit-identical to --spp 2^P - 1), so it "
                   "depends on this machine's speed; the passes and samples are recorded in the EXR")
        ->check(CLI::Validator(
            [](std::string& value) {
                char* end = nullptr;
                errno = 0;
                const double seconds = std::strtod(value.c_str(), &end);
                if (value.empty() || end == value.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(seconds) ||
                    seconds <= 0.0 || seconds > kMaxTimeLimitSeconds)
                    return std::string("must be a number of seconds, > 0 and at most ") +
                           std::to_string(int64_t(kMaxTimeLimitSeconds)) + " (e.g. 60 or 0.5)";
                return std::string();
            },
            "SECONDS"));
    cmd.add_option("--resolution", o.resolution, "Image size WxH, overriding the scene's film (e.g. 640x480)");
    cmd.add_option("--crop", o.crop, "Render only the window x,y,width,height of the film (after --resolution), "
                   "overriding the scene's crop; its pixels equal the full render's (e.g. 16,8,32,24)");
    cmd.add_option("--threads", o.threads,
                   "Shading threads; 0 (the default) = all cores (with --workers: per worker, default cores / N)")
        ->check(CLI::Range(0, 4096));
    cmd.add_option("--seed", o.seed, "Random seed, 0 ... 2^64-1 as a decimal integer; equal seeds give bit-identical images "
                                     "(default 0)")
        ->transform(CLI::Validator(
            [](std::string& value) {
                // Exactly a decimal number in range: not -1 (which would wrap), 1e3, 0x10 or 2^64.
                static const std::regex digits("^[0-9]{1,20}$");
                errno = 0;
                if (!std::regex_match(value, digits)) return std::string("must be a decimal integer 0 ... 18446744073709551615");
                (void)std::strtoull(value.c_str(), nullptr, 10);
                return errno == ERANGE ? std::string("is above 2^64-1 = 18446744073709551615") : std::string();
            },
            "0..2^64-1"));
    cmd.add_option("--max-depth", o.maxDepth,
                    "Path length as Mitsuba's maxDepth: 1 emitters only, 2 direct + single scattering, -1 unlimited "
                    "(default: the scene's integrator)")
        ->check(CLI::Validator(
            [](std::string& value) {
                const int depth = std::atoi(value.c_str());
                return depth == -1 || (depth >= 1 && depth <= 100000) ? std::string()
                                                                     : std::string("must be -1 or 1..100000");
            },
            "-1 or 1..100000"));
    cmd.add_option("--vrls", o.vrls, "vrl, vrl-lightcuts: target number of VRLs (vpl-lightcuts: of VPLs); whole light paths are traced "
                   "until reached (default 100000)")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 32));
    cmd.add_option("--light-paths", o.lightPaths, "vrl: trace exactly this many light paths (overrides --vrls)")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 40));
    cmd.add_option("--vrl-samples", o.vrlSamples, "vrl: (u, v) samples per VRL and camera segment (default 1)")
        ->check(CLI::Range(1, 1024));
    cmd.add_option("--transport", o.transport,
                    "vrl: parts to render, comma-separated: surface (a), single (b), medium-surface (c), multiple (d); "
                    "each is also written as an EXR layer (default: all four)");
    cmd.add_option("--error", o.error,
                    "vrl-lightcuts, vpl-lightcuts: relative error threshold; a node is refined while its bound exceeds this times "
                    "the current estimate (default 0.02)")
        ->check(CLI::Range(0.0f, 1e6f));
    cmd.add_option("--max-cut", o.maxCut, "vrl-lightcuts, vpl-lightcuts: most nodes in one cut, a safety valve (default 4096)")
        ->check(CLI::Range(1u, 1u << 30));
    cmd.add_option("--exact-distance-below", o.exactDistanceBelow,
                    "vrl-lightcuts: nodes with at most this many VRLs take their distance to the camera ray from "
                    "their VRLs rather than their box (default 32)")
        ->check(CLI::Range(0u, 1u << 20));
    cmd.add_option("--hg-epsilon", o.hgEpsilon,
                   "vrl-lightcuts: bound Henyey-Greenstein media by the paper's heuristic, the isotropic bound x "
                   "(1 + this), instead of the proven bound over cones of directions (the default); vpl-lightcuts: "
                   "always this heuristic (default 1)")
        ->check(CLI::Range(0.0f, 1e6f));
    cmd.add_flag("--glossy-heuristic", o.glossyHeuristic,
                 "vrl-lightcuts: bound part (c) at glossy surfaces by the heuristic (twice the largest f|cos| towards "
                 "ten points of a node's box; faster, may be exceeded) instead of the proven bound over the cone of "
                 "directions (the default for rough plastic and rough conductor with Beckmann or GGX)");
    cmd.add_option("--partition-size", o.partitionSize,
                    "vrl-lightcuts, vpl-lightcuts: lights per partition before agglomerative clustering (default 2048)")
        ->check(CLI::Range(2u, 1u << 30));
    cmd.add_option("--cut-size", o.cutSize,
                   "vrl-stochastic: nodes per stochastic cut, one VRL drawn under each (per camera segment and surface "
                   "point, per sample; default 32)")
        ->check(CLI::Range(1u, 1u << 20));
    cmd.add_option("--vrl-sets", o.vrlSets,
                   "vrl-stochastic: independent VRL sets of --vrls each (own light paths, own trees); camera sample s "
                   "uses set s mod this, so the image converges to the true transport, not one set's (default 1)")
        ->check(CLI::Range(1u, uint32_t(kMaxVrlSets)));
    cmd.add_option("--distance-samples", o.distanceSamples,
                   "vpl, vpl-lightcuts: stratified distance samples per camera segment, each gathering the VPLs "
                   "(by a cut for vpl-lightcuts); their cost grows with it, the noise of the distance sampling "
                   "falls (default " + std::to_string(kDefaultVplDistanceSamples) + ")")
        ->check(CLI::Range(1u, uint32_t(kMaxVplDistanceSamples)));
    cmd.add_option("--shading-points", o.shadingPoints,
                   "vrl, vrl-lightcuts, vpl, vpl-lightcuts: shade parts (c), (d) and (b)'s surface VPLs, which these "
                   "methods evaluate once per pixel, at K x K stratified points of the pixel and average them: their "
                   "noise between seeds at edges and on textures falls, their cost grows K^2 (default 1)")
        ->check(CLI::Range(1u, uint32_t(kMaxShadingPointsPerSide)));
    cmd.add_option("--surface-vpls", o.surfaceVpls,
                   "vrl, vrl-lightcuts: the most surface VPLs for part (b)'s surface light, deposited by the first "
                   "light paths until the limit (fewer paths: a noisier, not a darker, part (b)); 0: none, part (b) "
                   "path-samples its surface light (default: as many as --vrls, or 4 per light path)")
        ->check(CLI::Range(uint64_t(0), uint64_t(1) << 40));
    cmd.add_flag("--pixel-centres", o.pixelCentres,
                 "Camera rays through pixel centres, the paper's setting (default: jittered inside each pixel, "
                 "antialiased, as Mitsuba and pbrt do; still bit-identical across threads and workers)");
    cmd.add_flag("-q,--quiet", o.quiet, "Warnings and errors only: no progress bars, no summary");
}

void warnIneffectiveFlags(const CLI::App& command, RenderMethod method, bool distributed) {
    // Each flag and the setting it sets; the method table (render_method.h) says which methods read it.
    struct Rule {
        const char* flag;
        bool MethodReads::*setting;
        const char* note;  // said after the methods that read it
    };
    const Rule rules[] = {
        {"--vrls", &MethodReads::lightCount, ""},
        {"--light-paths", &MethodReads::lightCount, ""},
        {"--transport", &MethodReads::transports, " (path renders everything)"},
        {"--vrl-samples", &MethodReads::vrlSamples, ""},
        {"--error", &MethodReads::cutError, ""},
        {"--max-cut", &MethodReads::cutError, ""},
        {"--hg-epsilon", &MethodReads::cutError, ""},
        {"--partition-size", &MethodReads::partitionSize, ""},
        {"--cut-size", &MethodReads::stochasticCutSize, ""},
        {"--exact-distance-below", &MethodReads::vrlClusterBounds, ""},
        {"--glossy-heuristic", &MethodReads::vrlClusterBounds, ""},
        {"--distance-samples", &MethodReads::vplDistanceSamples, ""},
        {"--shading-points", &MethodReads::shadingPoints, " (vrl-stochastic shades every sample)"},
        {"--surface-vpls", &MethodReads::surfaceVplLimit, ""},
    };
    const MethodTraits& traits = methodTraits(method);
    for (const Rule& rule : rules)
        if (!(traits.reads.*rule.setting) && command.count(rule.flag) > 0)
            spdlog::warn("{} has no effect with --method {}: it acts on {}{} only", rule.flag, traits.name,
                         methodsReading(rule.setting), rule.note);
    const bool virtualLights = traits.lights != VirtualLights::None;
    if (virtualLights && command.count("--light-paths") > 0 && command.count("--vrls") > 0)
        spdlog::warn("--vrls has no effect with --light-paths: exactly the given light paths are traced");
    if (!distributed && command.get_name() == "render" && command.count("--tile-size") > 0)
        spdlog::warn("--tile-size has no effect without --workers: the embedded render schedules its own tiles");
}

void checkLightMemory(const RenderSettings& settings, uint64_t memoryBytes) {
    const uint64_t need = estimateLightMemoryBytes(settings);
    if (need <= memoryBytes) return;
    char message[512];
    std::snprintf(message, sizeof message,
                  "--vrls %llu%s: the %s and their light structures need about %.1f GiB (%.0f bytes each), more than "
                  "this machine's %.1f GiB of memory; lower --vrls%s",
                  (unsigned long long)settings.vrlCount, settings.vrlSets > 1 ? " in each VRL set" : "",
                  usesVpls(settings.method) ? "VPLs" : "VRLs", double(need) / double(1ull << 30),
                  double(need) / (double(std::max<uint64_t>(1, settings.vrlCount)) * std::max(1, settings.vrlSets)),
                  double(memoryBytes) / double(1ull << 30),
                  settings.vrlSets > 1                             ? " or --vrl-sets"
                  : settings.surfaceVplLimit != kAutoSurfaceVpls && usesSurfaceVpls(settings) ? " or --surface-vpls"
                                                                                  : "");
    throw std::invalid_argument(message);
}

v1::RenderParameters toRenderParameters(const RenderCommandOptions& o) {
    v1::RenderParameters p;
    p.set_method(o.method);
    p.set_samples_per_pixel(o.spp);
    p.set_time_limit_seconds(o.timeLimit);
    p.set_seed(o.seed);
    p.set_jitter(!o.pixelCentres);
    p.set_max_depth(o.maxDepth);
    if (!o.resolution.empty()) {
        const auto [w, h] = util::parseResolution(o.resolution, kMaxFilmSide, kMaxFilmPixels);
        p.set_width(uint32_t(w));
        p.set_height(uint32_t(h));
    }
    if (!o.crop.empty()) {  // checked against the film by rpc::resolveJob
        std::smatch m;
        if (!std::regex_match(o.crop, m, std::regex("^([0-9]{1,9}),([0-9]{1,9}),([0-9]{1,9}),([0-9]{1,9})$")))
            throw std::invalid_argument("--crop expects x,y,width,height in film pixels (e.g. 16,8,32,24), got '" +
                                        o.crop + "'");
        auto& c = *p.mutable_crop();
        c.set_x(std::stoul(m[1])), c.set_y(std::stoul(m[2])), c.set_width(std::stoul(m[3])), c.set_height(std::stoul(m[4]));
    }
    p.set_transport(o.transport);
    p.set_vrl_count(o.vrls);
    p.set_light_paths(o.lightPaths);
    p.set_vrl_samples(o.vrlSamples);
    p.set_error(o.error);
    p.set_max_cut(o.maxCut);
    p.set_exact_distance_below(o.exactDistanceBelow);
    p.set_hg_epsilon(o.hgEpsilon.value_or(ClusterBoundSettings{}.anisotropyEpsilon));
    p.set_hg_epsilon_bound(o.hgEpsilon.has_value());
    p.set_glossy_heuristic_bound(o.glossyHeuristic);
    p.set_partition_size(o.partitionSize);
    p.set_cut_size(o.cutSize);
    p.set_vrl_sets(o.vrlSets);
    p.set_vpl_distance_samples(o.distanceSamples);
    p.set_shading_points(o.shadingPoints);
    // The spec's -1 is none, its 0 the default.
    if (o.surfaceVpls) p.set_surface_vpls(*o.surfaceVpls == 0 ? -1 : int64_t(*o.surfaceVpls));
    return p;
}

v1::JobSpec makeJobSpec(const RenderCommandOptions& o, const std::map<std::string, std::string>& defines) {
    v1::JobSpec spec;
    spec.mutable_defines()->insert(defines.begin(), defines.end());
    *spec.mutable_parameters() = toRenderParameters(o);
    spec.set_tile_size(o.tileSize);
    spec.set_name(o.scene);
    spec.set_medium(o.medium);
    return spec;
}

}  // namespace vrl::client
