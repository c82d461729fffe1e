// stochastic_bench: stochastic VRL Lightcuts (vrl-stochastic) against plain VRLs
// and deterministic VRL Lightcuts, for part (d) (or (c) with --part
// medium-surface), on one scene at several VRL counts N.
//
// The error is the relative RMSE (luminance, image_metrics.h) against the
// converged part of the *same* VRL set: the mean of `--reference-runs` plain-VRL
// renders with independent (u, v) samples. That is what every method here
// estimates (a cut cannot remove the error of the VRL set itself, which all
// three share). Plain VRLs (one (u, v) sample per VRL, another seed than the
// reference's) and Lightcuts at --error are rendered once each; vrl-stochastic
// at 1, 2, 4, ... samples per pixel until it has run --time-factor times the
// Lightcuts time. Per N it prints each method's time and error, and:
//   st_eq_plain: the time vrl-stochastic needs to reach plain's error (the
//     Monte Carlo rate error ~ t^-1/2 from its last measured point; '*' when
//     extrapolated past the measured range), and plain's time over it;
//   st_at_lc: the error of vrl-stochastic at the Lightcuts time (interpolated
//     on the same rate between the measured points) against the Lightcuts error;
//   st_eq_lc: the time vrl-stochastic needs to reach the Lightcuts error, and
//     the Lightcuts time over it;
//   #Eval (VRL estimates) and importances per pixel and sample.
// Timings are wall-clock, one run each, on whatever cores TBB gets: compare
// ratios within one run, not seconds.
#include "render/core/timing.h"
#include "render/image/image_metrics.h"
#include "render/integrators/transport_integrator.h"
#include "render/lightcuts/light_tree.h"
#include "render/scene/scene.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "render/vrl/light_tracer.h"

#include <CLI/CLI.hpp>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>

using namespace vrl;

namespace {

enum class Method { Plain, Lightcuts, Stochastic };

struct Shading {
    Image image;
    double seconds = 0.0;
    double evaluated = 0.0, importances = 0.0;  // per shaded pixel and sample
};

// The part on every `stride`-th pixel in x and y (the others stay black), with
// `spp` samples per pixel (only vrl-stochastic draws more than one).
Shading shade(const Scene& scene, const VrlSet& vrls, const LightTree& tree, Method method, float error, int cutSize,
              int spp, int stride, uint64_t seed, bool surfacePart, int vrlSamples = 1) {
    TransportIntegratorSettings settings;
    settings.vrlSamples = vrlSamples;
    settings.transports = TransportSelection::parse(surfacePart ? "medium-surface" : "multiple");
    settings.cut.errorThreshold = error;
    settings.cut.stochasticCutSize = uint32_t(cutSize);
    settings.stochastic = method == Method::Stochastic;
    const TransportIntegrator integrator(scene, vrls, settings, method == Method::Plain ? nullptr : &tree);
    const PerspectiveCamera& camera = scene.camera();
    Shading out;
    out.image = Image(camera.width(), camera.height());
    std::atomic<uint64_t> evaluated{0}, importances{0}, pixels{0};
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(0, (camera.height() + stride - 1) / stride, [&](int row) {
        const int y = row * stride;
        for (int x = 0; x < camera.width(); x += stride) {
            Rng rng(seed, uint64_t(y) * camera.width() + x);
            CutStatistics stats;
            Rgb sum(0.0f);
            for (int s = 0; s < spp; ++s) {
                const auto parts = integrator.virtualLightParts(camera.generateRay(x + 0.5f, y + 0.5f), rng, &stats, &stats);
                sum += surfacePart ? parts.mediumSurface : parts.multiple;
            }
            out.image.at(x, y) = sum / float(spp);
            evaluated += stats.evaluated, importances += stats.importanceEvaluations, ++pixels;
        }
    });
    out.seconds = secondsSince(start);
    const double samples = double(pixels.load()) * spp;
    out.evaluated = double(evaluated.load()) / samples;
    out.importances = double(importances.load()) / samples;
    return out;
}

Image mean(const std::vector<Image>& images) {
    Image out(images[0].width(), images[0].height());
    for (const Image& image : images)
        for (int y = 0; y < out.height(); ++y)
            for (int x = 0; x < out.width(); ++x) out.at(x, y) += image.at(x, y) / float(images.size());
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Stochastic VRL Lightcuts against plain VRLs and VRL Lightcuts (part (d), or part (c))"};
    std::string part = "multiple";
    std::string scenePath = "scenes/smoke-room.xml";
    std::vector<uint64_t> counts = {10000, 100000};
    std::string resolution = "64x48";
    float error = 0.02f;
    std::vector<int> cutSizes = {32};
    int referenceRuns = 4;
    double timeFactor = 2.0;
    int maxSpp = 4096;
    int vrlSamples = 1;
    uint64_t strideAbove = 200000;
    int stride = 4;
    std::vector<std::string> defines;
    app.add_option("--scene", scenePath, "Scene file (default scenes/smoke-room.xml)");
    app.add_option("-D,--define", defines, "Override a scene <default>: -D name=value (repeatable)");
    app.add_option("--vrls", counts, "VRL counts to run (default 10000 100000)");
    app.add_option("--resolution", resolution, "Image size WxH (default 64x48)");
    app.add_option("--error", error, "Lightcuts error threshold (default 0.02)");
    app.add_option("--cut-size", cutSizes, "Stochastic cut sizes K to run (default 32)")->check(CLI::Range(1, 1 << 20));
    app.add_option("--reference-runs", referenceRuns, "Plain-VRL renders averaged into the reference (default 4)")
        ->check(CLI::Range(1, 1024));
    app.add_option("--time-factor", timeFactor, "Stochastic runs up to this times the Lightcuts time (default 2)");
    app.add_option("--vrl-samples", vrlSamples, "vrl-stochastic: (u, v) samples per drawn VRL (default 1)")
        ->check(CLI::Range(1, 1024));
    app.add_option("--max-spp", maxSpp, "Most stochastic samples per pixel (default 4096)");
    app.add_option("--stride-above", strideAbove, "Above this N, shade every --stride-th pixel in x and y (default 200000)");
    app.add_option("--stride", stride, "Pixel stride for large N (default 4: 1/16 of the pixels)");
    app.add_option("--part", part, "Transport part: multiple (d, default) or medium-surface (c)")
        ->check(CLI::IsMember({"multiple", "medium-surface"}));
    CLI11_PARSE(app, argc, argv);
    const bool surfacePart = part == "medium-surface";

    ParseOptions parseOptions;
    for (const auto& d : defines) {
        const auto eq = d.find('=');
        if (eq == std::string::npos) {
            std::fprintf(stderr, "-D expects name=value, got '%s'\n", d.c_str());
            return 2;
        }
        parseOptions.defines[d.substr(0, eq)] = d.substr(eq + 1);
    }
    SceneDescription description = parseMitsubaScene(scenePath, parseOptions);
    int w = 0, h = 0;
    if (std::sscanf(resolution.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1) {
        std::fprintf(stderr, "bad --resolution '%s'\n", resolution.c_str());
        return 2;
    }
    description.sensor.width = w;
    description.sensor.height = h;
    const auto scene = Scene::build(description);
    std::printf("scene %s, %dx%d, part %s, Lightcuts error %.3f\n", scenePath.c_str(), w, h,
                surfacePart ? "(c)" : "(d)", error);
    std::printf("errors: relative RMSE against the same VRL set's converged part (mean of %d plain renders)\n",
                referenceRuns);
    for (uint64_t n : counts) {
        LightTracingSettings tracing;
        tracing.targetVrls = n;
        tracing.maxDepth = description.integrator.maxDepth;
        const VrlSet vrls = traceVrls(*scene, tracing);
        const LightTree tree = LightTree::build(vrls.vrls);
        const int s = n > strideAbove ? stride : 1;
        std::printf("\nN = %zu VRLs%s\n", vrls.vrls.size(), s > 1 ? " (1/16 of the pixels)" : "");
        std::vector<Image> references;
        for (int r = 0; r < referenceRuns; ++r)
            references.push_back(shade(*scene, vrls, tree, Method::Plain, error, 1, 1, s, 1000 + r, surfacePart).image);
        const Image reference = mean(references);
        const Shading plain = shade(*scene, vrls, tree, Method::Plain, error, 1, 1, s, 1, surfacePart);
        const Shading cuts = shade(*scene, vrls, tree, Method::Lightcuts, error, 1, 1, s, 1, surfacePart);
        const double plainError = compareImages(reference, plain.image).relativeRmse;
        const double cutsError = compareImages(reference, cuts.image).relativeRmse;
        std::printf("  %-22s %9.3f s  relRMSE %.5f\n", "plain VRLs", plain.seconds, plainError);
        std::printf("  %-22s %9.3f s  relRMSE %.5f  #Eval %.0f per pixel\n", "VRL Lightcuts", cuts.seconds, cutsError,
                    cuts.evaluated);
        for (const int cutSize : cutSizes) {
            struct Point {
                int spp;
                double seconds, error;
            };
            std::vector<Point> points;
            for (int spp = 1; spp <= maxSpp; spp *= 2) {
                const Shading st =
                    shade(*scene, vrls, tree, Method::Stochastic, error, cutSize, spp, s, 1, surfacePart, vrlSamples);
                const double e = compareImages(reference, st.image).relativeRmse;
                points.push_back({spp, st.seconds, e});
                std::printf("  vrl-stochastic K %4d %5d spp %9.3f s  relRMSE %.5f  #Eval %.1f, importances %.0f per pixel and sample\n",
                            cutSize, spp, st.seconds, e, st.evaluated, st.importances);
                std::fflush(stdout);
                if (st.seconds > timeFactor * cuts.seconds) break;
            }
            // Time to reach error e on the Monte Carlo rate through the point p: t_p (e_p / e)^2.
            const auto timeFor = [&](double target, bool& extrapolated) {
                for (const Point& p : points)
                    if (p.error <= target) {
                        extrapolated = false;
                        return p.seconds * (p.error / target) * (p.error / target);
                    }
                extrapolated = true;
                const Point& p = points.back();
                return p.seconds * (p.error / target) * (p.error / target);
            };
            const auto errorAt = [&](double seconds) {
                const Point* p = &points.back();
                for (const Point& q : points)
                    if (q.seconds >= seconds) {
                        p = &q;
                        break;
                    }
                return p->error * std::sqrt(p->seconds / seconds);
            };
            bool extrapolated = false;
            const double tPlain = timeFor(plainError, extrapolated);
            std::printf("  st_eq_plain: %.3f s%s to reach plain's error: plain VRLs take %.2fx that time\n", tPlain,
                        extrapolated ? "*" : "", plain.seconds / tPlain);
            std::printf("  st_at_lc:    relRMSE %.5f at the Lightcuts time (Lightcuts %.5f): %s\n", errorAt(cuts.seconds),
                        cutsError, errorAt(cuts.seconds) < cutsError ? "stochastic lower" : "Lightcuts lower");
            const double tCuts = timeFor(cutsError, extrapolated);
            std::printf("  st_eq_lc:    %.3f s%s to reach the Lightcuts error: VRL Lightcuts take %.2fx that time\n", tCuts,
                        extrapolated ? "*" : "", cuts.seconds / tCuts);
        }
        std::fflush(stdout);
    }
    return 0;
}
