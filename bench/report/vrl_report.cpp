// vrl_report: error against run time for every method on the benchmark scenes
// (Vibert et al. 2019, Figures 3, 4, 6 and Table 1). For each scene: two
// references, the whole image (path tracer; light tracing connected to the
// camera where the light arrives through glass) and part (d) alone (plain VRLs
// over independent VRL sets), each two independent halves whose
// difference estimates its noise, rendered in resumable chunks and kept in
// bench/references by a hash of the scene's files, the settings and the method;
// then every method over a range of settings, for the whole image and for part
// (d) alone, recording wall time (light tracing, tree build and shading; the
// scene load is common to all and left out), RMSE, relative RMSE, SMAPE and the
// cut statistics, with the noise rule (an error below 3x the reference's own
// is marked and left out of every ratio). Writes results.csv, speedup.csv,
// false-colour #Eval / #Inter images, previews, summary.md (tables, ratios,
// verdicts, what to use when) and (through bench/plot_report.py) the plots.
#include "bench/report/benchmark_scenes.h"
#include "bench/report/curve_ratios.h"
#include "bench/report/false_colour.h"

#include "render/core/timing.h"
#include "render/image/exr_io.h"
#include "render/image/image_metrics.h"
#include "render/image/preview_image.h"
#include "render/integrators/light_tracing_reference.h"
#include "render/render_metadata.h"
#include "render/renderer.h"
#include "render/scene/scene.h"
#include "render/scene_io/medium_fill.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "render/vrl/light_tracer.h"
#include "util/atomic_file.h"
#include "util/hash.h"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

namespace fs = std::filesystem;
using namespace vrl;
using namespace vrl::report;

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
    fs::path out = "report";
    bool buildReferences = false;  // --references: build the missing references, then stop
    double referenceMinutes = 0.0;  // --references: stop after this long (0: no limit); a later run resumes
    int partReferenceChunks = 0;  // --part-reference-chunks: every scene's part (d) reference this long (0: the scene's)
    fs::path references = fs::path(VRL_SOURCE_DIR) / "bench" / "references";  // --quick: OUT/cache
    fs::path shared = fs::path(VRL_SOURCE_DIR).parent_path() / "shared" / "scenes";
    bool quick = false;
    std::vector<std::string> only;
    int threads = 0;
    std::string python = "/usr/bin/python3";
    bool plots = true;
};

// The noise rule: an error below kNoiseFactor x the reference's own estimated
// error cannot be told from the reference's noise; such a run is marked and
// left out of every ratio.
constexpr double kNoiseFactor = 3.0;

// One point of a curve: run.repeats renders, each from its own seed. `seconds`:
// their mean time; `metrics`: their root-mean-square RMSE and relative RMSE (the
// expected squared error is what an unbiased method's time buys down, as 1/time),
// mean SMAPE and mean luminances, summed pixel counts; rmseMin, rmseMax: the
// spread of their RMSEs; `stats`: the first render's cut statistics.
struct RunResult {
    std::string scene;
    MethodRun run;
    double seconds = 0.0;
    ImageErrorMetrics metrics;
    RenderStatistics stats;
    double referenceNoiseRmse = 0.0;
    int renders = 1;
    double rmseMin = 0.0, rmseMax = 0.0;
    bool belowNoise() const { return metrics.rmse < kNoiseFactor * referenceNoiseRmse; }
};

// results.csv's distance_samples: the VPL methods' distance samples per camera segment, 0 for the others.
int distanceSamplesColumn(const MethodRun& run) {
    if (!usesVpls(run.method)) return 0;
    return run.distanceSamples > 0 ? run.distanceSamples : RenderSettings{}.vplDistanceSamples;
}

// The point of `renders` (each one render's time and metrics against the same reference).
void combineRenders(RunResult& r, const std::vector<std::pair<double, ImageErrorMetrics>>& renders) {
    const double n = double(renders.size());
    double seconds = 0.0, squared = 0.0, relativeSquared = 0.0, smape = 0.0, meanReference = 0.0, meanTest = 0.0;
    ImageErrorMetrics m;
    bool unmeasured = false;  // a render that compared no pixel (NaN RMSE) makes the whole point NaN, its range too
    r.rmseMin = INFINITY, r.rmseMax = -INFINITY;
    for (const auto& [time, e] : renders) {
        seconds += time;
        squared += e.rmse * e.rmse;
        relativeSquared += e.relativeRmse * e.relativeRmse;
        smape += e.smape;
        meanReference += e.meanReference;
        meanTest += e.meanTest;
        m.pixels += e.pixels;
        m.nonFinitePixels += e.nonFinitePixels;
        r.rmseMin = std::min(r.rmseMin, e.rmse);
        r.rmseMax = std::max(r.rmseMax, e.rmse);
        unmeasured |= std::isnan(e.rmse);
    }
    if (unmeasured) r.rmseMin = r.rmseMax = NAN;
    m.rmse = std::sqrt(squared / n);
    m.relativeRmse = std::sqrt(relativeSquared / n);
    m.smape = smape / n, m.meanReference = meanReference / n, m.meanTest = meanTest / n;
    r.seconds = seconds / n;
    r.metrics = m;
    r.renders = int(renders.size());
}

struct SpeedupResult {
    std::string scene, kind;  // kind: VRL, VPL (deterministic cuts) or VRL-stochastic
    uint64_t lights = 0;
    double bruteSecondsPerPixel = 0.0, lightcutsSecondsPerPixel = 0.0;
    double meanEval = 0.0, meanInter = 0.0;
    double error = 0.0;  // the cut's relative RMSE against brute force on these pixels (stochastic: the same, by design)
};

// The report's relative RMSE (image_metrics.h: per pixel against R^2 + eps) of
// per-pixel luminances.
double relativeRmse(const std::vector<float>& test, const std::vector<float>& reference) {
    const auto row = [](const std::vector<float>& values) {
        Image image(int(values.size()), 1);
        for (size_t k = 0; k < values.size(); ++k) image[k] = Rgb(values[k]);  // grey: its luminance is the value
        return image;
    };
    return compareImages(row(reference), row(test)).relativeRmse;
}

// The two references of a scene: the whole image (path tracer, or light tracing
// connected to the camera: BenchmarkScene::referenceLightPaths) and part (d) alone
// (plain VRLs over many independent VRL sets).
enum class ReferencePart { Image, Multiple };

struct ReferenceInfo {
    ReferencePart part = ReferencePart::Image;
    std::string method;  // how it was made, for the summary
    int spp = 0;
    double seconds = 0.0;  // when rendered in this run or recorded in the cache
    bool cached = false;
    bool incomplete = false;  // stopped at the time limit; its chunks so far are kept in a .partial.exr
    int chunks = 0, wantedChunks = 0;  // per half: stored, and what the scene asks for (more: short)
    double noiseRmse = 0.0, noiseRelativeRmse = 0.0, noiseSmape = 0.0;
    fs::path file;
};

// Progress lines with the elapsed time of the whole report.
class Log {
public:
    explicit Log(Clock::time_point start) : start_(start) {}
    template <class... Args>
    void line(const char* format, Args... args) const {
        const double t = secondsSince(start_);
        std::fprintf(stderr, "[%3d:%02d] ", int(t) / 60, int(t) % 60);
        std::fprintf(stderr, format, args...);
        std::fputc('\n', stderr);
    }

private:
    Clock::time_point start_;
};

std::string hashSceneAndSettings(const BenchmarkScene& s, const std::string& settings) {
    ParseOptions options;
    options.defines = s.defines;
    std::vector<fs::path> files{s.file};
    options.onFileReferenced = [&](const fs::path& f) { files.push_back(f); };
    (void)parseMitsubaScene(s.file, options);
    std::string all = settings;
    for (const auto& [name, value] : s.defines) all += "\n-D " + name + "=" + value;
    for (const auto& f : files) {
        std::ifstream in(f, std::ios::binary);
        std::ostringstream bytes;
        bytes << in.rdbuf();
        all += "\n" + f.filename().string() + ":" + util::sha256Hex(bytes.str());
    }
    return util::sha256Hex(all).substr(0, 16);
}

std::unique_ptr<Scene> loadScene(const BenchmarkScene& s) {
    ParseOptions options;
    options.defines = s.defines;
    SceneDescription description = parseMitsubaScene(s.file, options);
    if (!s.medium.empty()) fillWithMedium(description, parseFillMedium(s.medium));
    description.sensor.width = s.width;
    description.sensor.height = s.height;
    return Scene::build(description);
}

// The renders of chunk `chunk` of one half of a reference, whose mean is the
// chunk: the path tracer's one render, or part (d)'s one per VRL set (plain
// VRLs, each set traced from its own seed, so the mean converges to the true
// transport, not one set's).
std::vector<RenderSettings> referenceChunk(const BenchmarkScene& s, ReferencePart part, uint64_t half, int chunk) {
    const uint64_t stream = 2 * uint64_t(chunk) + half;  // the halves and chunks: disjoint streams
    if (part == ReferencePart::Image)
        return {settingsFor(s, MethodRun{RenderMethod::Path, 0, std::max(1, s.referenceSpp / 2 / kReferenceChunks)},
                            1000003 + stream)};
    std::vector<RenderSettings> sets;
    for (int k = 0; k < s.partReferenceSets; ++k) {
        RenderSettings settings =
            settingsFor(s, MethodRun{RenderMethod::Vrl, s.partReferenceVrls, 1}, 2000003 + stream * 4096 + uint64_t(k));
        settings.transports = TransportSelection::parse("multiple");
        sets.push_back(settings);
    }
    return sets;
}

constexpr float kReferencePixelFootprint = 0.25f;

// A whole-image reference by light tracing connected to the camera (BenchmarkScene::referenceLightPaths).
bool lightTracedReference(const BenchmarkScene& s, ReferencePart part) {
    return part == ReferencePart::Image && s.referenceLightPaths > 0;
}

// Chunk `chunk` of one half of a reference: the mean of referenceChunk's renders,
// or one light-tracing render from its own seed.
Image renderReferenceChunk(const BenchmarkScene& s, const Scene& scene, ReferencePart part, uint64_t half, int chunk) {
    if (lightTracedReference(s, part)) {
        LightTracingReferenceSettings settings;
        settings.lightPaths = std::max<uint64_t>(1, s.referenceLightPaths / 2 / kReferenceChunks);
        settings.samplesPerPixel = std::max(1, s.referenceSpp / 2 / kReferenceChunks);
        settings.seed = 3000003 + 2 * uint64_t(chunk) + half;
        settings.maxDepth = s.maxDepth;
        // As the runs' rays (settingsFor: RenderSettings::jitter is false): part 2 at pixel centres,
        // part 1 over the centred quarter of each pixel's width. Measured on volumetric-caustic
        // (part 1, luminance): whole pixels against that quarter differ by RMSE 0.17 (the light's
        // glow falls off within a pixel), the quarter against a sixteenth by none that 32M light
        // paths could resolve (below 0.02); the quarter's noise is 4x the whole pixel's.
        settings.pixelCentres = true;
        settings.pixelFootprint = kReferencePixelFootprint;
        return renderLightTracingReference(scene, settings);
    }
    const std::vector<RenderSettings> renders = referenceChunk(s, part, half, chunk);
    Image mean(s.width, s.height);
    for (const RenderSettings& settings : renders) {
        const Image one = render(scene, settings).image;
        for (size_t i = 0; i < one.pixelCount(); ++i) mean[i] = mean[i] + one[i] * (1.0f / float(renders.size()));
    }
    return mean;
}

// The commit of the source tree, "+changes" after it where tracked files differ
// from it (what a reference or a check was computed by).
std::string gitCommit() {
    const std::string git = "git -C '" + std::string(VRL_SOURCE_DIR) + "' ";
    const std::string command =
        git + "rev-parse --short HEAD 2>/dev/null && { " + git + "diff --quiet HEAD -- 2>/dev/null || echo +changes; }";
    std::string out;
    if (FILE* pipe = popen(command.c_str(), "r")) {
        char buffer[64];
        while (std::fgets(buffer, sizeof buffer, pipe)) out += buffer;
        pclose(pipe);
    }
    std::erase(out, '\n');
    while (!out.empty() && out.back() == ' ') out.pop_back();
    return out.empty() ? "unknown" : out;
}

// What a reference of `chunks` chunks per half is: the key its file is named by
// (a hash of it and the scene's files), the file, and how it was made. A part (d)
// reference of more than kReferenceChunks chunks is built in two stages: the
// kReferenceChunks-chunk reference (its own file, made first), then the chunks
// after those, continuing its halves' running means as stored; a build from
// nothing goes through the same two stages and gives the same bits.
struct ReferenceSpec {
    int chunks = kReferenceChunks;
    std::string key, what, method;
    int spp = 0;  // camera samples per pixel in all (part (d): one per VRL set)
    int sets = 0;  // part (d): VRL sets in all
    uint64_t lightPaths = 0;
    bool lightTraced = false;
    fs::path file;
};

ReferenceSpec referenceSpec(const BenchmarkScene& s, ReferencePart part, const fs::path& dir, int chunks) {
    const RenderSettings first = referenceChunk(s, part, 0, 0).front();
    const bool image = part == ReferencePart::Image;
    ReferenceSpec spec;
    spec.chunks = chunks;
    spec.what = image ? "reference" : "part (d) reference";
    const int perHalf = chunks * first.samplesPerPixel;
    spec.sets = 2 * chunks * s.partReferenceSets;
    spec.lightTraced = lightTracedReference(s, part);
    spec.lightPaths = uint64_t(2 * chunks) * std::max<uint64_t>(1, s.referenceLightPaths / 2 / kReferenceChunks);
    std::string key = image ? "path spp=" + std::to_string(first.samplesPerPixel) + "x" + std::to_string(chunks) + "x2"
                            : "vrl transports=multiple vrls=" + std::to_string(first.vrlCount) + " spp=1 sets=" +
                                  std::to_string(s.partReferenceSets) + "x" + std::to_string(chunks) + "x2";
    if (spec.lightTraced)
        key = "light tracing to the camera paths=" + std::to_string(spec.lightPaths) + " footprint=" +
              std::to_string(kReferencePixelFootprint) + " path tracer at pixel centres " + key;
    key += " maxDepth=" + std::to_string(s.maxDepth) + " size=" + std::to_string(s.width) + "x" +
           std::to_string(s.height) + " medium=" + s.medium + " version=" + VRL_VERSION;
    if (chunks > kReferenceChunks) key += " extends chunks=" + std::to_string(kReferenceChunks);
    spec.key = key;
    spec.file = dir / (s.name + (image ? "-reference-" : "-reference-d-") + hashSceneAndSettings(s, key) + ".exr");
    spec.method = spec.lightTraced
                      ? "light tracing to the camera, " + std::to_string(spec.lightPaths / 1000000) +
                            "M light paths over the centred quarter of each pixel's width, plus the path "
                            "tracer where the camera sees specular surfaces or "
                            "emitters, " + std::to_string(2 * perHalf) + " spp at pixel centres"
                  : image ? "path tracer, " + std::to_string(2 * perHalf) + " spp"
                          : "plain VRLs over " + std::to_string(spec.sets) + " independent VRL sets of " +
                                std::to_string(first.vrlCount);
    spec.spp = image ? 2 * perHalf : spec.sets;
    return spec;
}

const Image& layerNamed(const ImageSet& set, const std::string& name, const fs::path& file) {
    for (const auto& [layer, image] : set.layers)
        if (layer == name) return image;
    throw std::runtime_error("reference " + file.string() + " lacks its layer " + name + "; delete it");
}

// A reference's noise from its halves, into `info`: the mean of two halves has half
// the variance of one, so its RMSE against the truth is about RMSE(half1, half2) / 2
// (independent, equal variance).
void measureNoise(const ImageSet& set, const fs::path& file, ReferenceInfo& info) {
    const ImageErrorMetrics m = compareImages(layerNamed(set, "half1", file), layerNamed(set, "half2", file));
    info.noiseRmse = m.rmse / 2.0;
    info.noiseRelativeRmse = m.relativeRmse / 2.0;
    info.noiseSmape = m.smape / 2.0;  // SMAPE is not a variance; halving is only indicative
}

// SHA-256 of a reference's two halves' pixels (not the file's bytes, whose
// metadata holds timings): what a second stage was started from.
std::string halvesDigest(const ImageSet& set, const fs::path& file) {
    std::string bytes;
    for (const char* name : {"half1", "half2"}) {
        const Image& half = layerNamed(set, name, file);
        bytes.append(reinterpret_cast<const char*>(&half[0]), half.pixelCount() * sizeof(half[0]));
    }
    return util::sha256Hex(bytes);
}

// The command that extends scene `scene`'s part (d) reference to `chunks` chunks per half.
std::string extendCommand(const std::string& scene, int chunks) {
    return "vrl_report --references --scenes " + scene + " --part-reference-chunks " + std::to_string(chunks);
}

// The chunks per half a scene's reference asks for.
int referenceChunks(const BenchmarkScene& s, ReferencePart part) {
    return part == ReferencePart::Multiple ? std::max(kReferenceChunks, s.partReferenceChunks) : kReferenceChunks;
}

// Loads reference `spec` from `dir`, or renders it (resuming from the chunks a
// stopped run saved in a .partial.exr beside it; one of more than kReferenceChunks
// chunks from the kReferenceChunks-chunk reference, made first if missing) and
// stores it as half-float EXR (float where a value exceeds half's range) with its
// halves and, beside it, a text file with the settings, the code version and the
// estimated noise (also in `info`). An empty set with info.incomplete: stopped at
// the time limit.
ImageSet referenceSet(const BenchmarkScene& s, const Scene& scene, ReferencePart part, const ReferenceSpec& spec,
                      const fs::path& dir, const Log& log, ReferenceInfo& info, double minutes) {
    // `minutes`: the time limit of this call, both stages together (0: none).
    const auto describe = [&] {
        info.part = part;
        info.method = spec.method;
        info.spp = spec.spp;
        info.file = spec.file;
        info.chunks = spec.chunks;
    };
    describe();
    ImageSet set;
    if (fs::exists(spec.file)) {
        set = readExr(spec.file);
        info.cached = true;
        info.seconds = metadataNumber(set.metadata["vrl.report.seconds"]);
        log.line("%s: %s from the cache (%s)", s.name.c_str(), spec.what.c_str(), spec.file.filename().c_str());
        measureNoise(set, spec.file, info);
        return set;
    }
    const fs::path partial = fs::path(spec.file).replace_extension(".partial.exr");
    std::vector<Image> halves(2, Image(s.width, s.height));
    int done = 0;
    double seconds = 0.0;
    // The second stage: the kReferenceChunks-chunk reference it extends (made first
    // if missing, within the same time limit), and a digest of its halves, which a
    // partial of this stage must have been started from.
    ImageSet from;
    std::string base;
    fs::path firstFile;
    if (spec.chunks > kReferenceChunks) {
        const ReferenceSpec firstStage = referenceSpec(s, part, dir, kReferenceChunks);
        firstFile = firstStage.file;
        if (!fs::exists(firstStage.file))
            log.line("%s: the %d-chunk %s extends the %d-chunk one: that first", s.name.c_str(), spec.chunks,
                     spec.what.c_str(), kReferenceChunks);
        const auto entry = Clock::now();
        (void)referenceSet(s, scene, part, firstStage, dir, log, info, minutes);
        if (info.incomplete) return {};
        if (minutes > 0.0) minutes = std::max(1e-9, minutes - secondsSince(entry) / 60.0);
        seconds = info.seconds;
        describe();
        info.cached = false;
        from = readExr(firstStage.file);  // as stored (half floats), however it came to be
        base = halvesDigest(from, firstStage.file);
    }
    if (fs::exists(partial)) {  // resume from the chunks a stopped run saved
        ImageSet saved = readExr(partial);
        if (std::get<std::string>(saved.metadata["vrl.report.key"]) != spec.key || saved.layers.size() != 2)
            throw std::runtime_error(partial.string() + " belongs to other settings; delete it");
        if (!base.empty() && metadataText(saved.metadata["vrl.report.extends"]) != base)
            throw std::runtime_error(partial.string() + " was started from another " + firstFile.filename().string() +
                                     " than the one stored now; delete it");
        halves = {layerNamed(saved, "half1", partial), layerNamed(saved, "half2", partial)};
        done = std::get<int32_t>(saved.metadata["vrl.report.chunks"]);
        seconds = metadataNumber(saved.metadata["vrl.report.seconds"]);
        log.line("%s: %s: resuming after %d of %d chunks", s.name.c_str(), spec.what.c_str(), done, spec.chunks);
    } else if (!base.empty()) {  // the second stage from the first's halves
        halves = {layerNamed(from, "half1", firstFile), layerNamed(from, "half2", firstFile)};
        done = kReferenceChunks;
        log.line("%s: %s: extending %s from %d to %d chunks per half (%s)", s.name.c_str(), spec.what.c_str(),
                 firstFile.filename().c_str(), done, spec.chunks, spec.method.c_str());
    } else {
        log.line("%s: rendering the %s, %s in two halves of %d chunks (%dx%d)...", s.name.c_str(), spec.what.c_str(),
                 spec.method.c_str(), spec.chunks, s.width, s.height);
    }
    const auto start = Clock::now();
    while (done < spec.chunks) {
        for (uint64_t h = 0; h < 2; ++h) {
            const Image chunk = renderReferenceChunk(s, scene, part, h, done);
            for (size_t i = 0; i < chunk.pixelCount(); ++i)  // the running mean of the chunks
                halves[h][i] = halves[h][i] + (chunk[i] - halves[h][i]) * (1.0f / float(done + 1));
        }
        ++done;
        log.line("%s: %s: chunk %d of %d", s.name.c_str(), spec.what.c_str(), done, spec.chunks);
        if (done == spec.chunks) break;
        // Every chunk is kept (writeExr replaces the file atomically: a run killed at
        // any moment loses at most the chunk it was rendering); a later run resumes.
        ImageSet save;
        save.image = halves[0];
        save.layers = {{"half1", halves[0]}, {"half2", halves[1]}};
        save.metadata["vrl.report.key"] = spec.key;
        save.metadata["vrl.report.chunks"] = int32_t(done);
        save.metadata["vrl.report.seconds"] = seconds + secondsSince(start);
        if (!base.empty()) save.metadata["vrl.report.extends"] = base;
        fs::create_directories(dir);
        writeExr(partial, save);
        // At the time limit (after at least one chunk, so that every run makes progress): stop.
        if (minutes > 0.0 && secondsSince(start) > 60.0 * minutes) {
            log.line("%s: %s stopped at the time limit after %d of %d chunks (kept in %s; run again to go on)",
                     s.name.c_str(), spec.what.c_str(), done, spec.chunks, partial.filename().c_str());
            info.incomplete = true;
            return {};
        }
    }
    info.seconds = seconds + secondsSince(start);
    fs::remove(partial);
    Image mean(s.width, s.height);
    for (size_t i = 0; i < mean.pixelCount(); ++i) mean[i] = (halves[0][i] + halves[1][i]) * 0.5f;
    set.image = mean;
    set.layers = {{"half1", halves[0]}, {"half2", halves[1]}};
    RenderRecord record;
    record.scene = s.file.string();
    record.defines = s.defines;
    record.medium = s.medium;
    record.settings = referenceChunk(s, part, 0, 0).front();
    record.settings.samplesPerPixel = spec.spp;  // the chunks of the two halves together
    record.statistics.seconds = info.seconds;
    record.run = {{"halves", int32_t(2)}, {"chunks", int32_t(spec.chunks)}};
    if (part == ReferencePart::Multiple) record.run["vrlSets"] = int32_t(spec.sets);
    if (spec.lightTraced) {
        record.run["lightPaths"] = double(spec.lightPaths);
        record.run["estimator"] = std::string("light tracing to the camera");
    }
    writeRenderMetadata(record, scene.camera(), set.metadata);
    set.metadata["vrl.report.key"] = spec.key;
    set.metadata["vrl.report.seconds"] = info.seconds;
    set.metadata["vrl.report.commit"] = gitCommit();
    if (!base.empty()) set.metadata["vrl.report.extends"] = firstFile.filename().string() + " halves sha256 " + base;
    fs::create_directories(dir);
    try {
        writeExr(spec.file, set, ExrPixels::Half);
    } catch (const std::invalid_argument&) {  // a value beyond half's range
        writeExr(spec.file, set);
    }
    log.line("%s: %s done in %.1f s -> %s", s.name.c_str(), spec.what.c_str(), info.seconds, spec.file.string().c_str());
    // The record beside it, for a reader of bench/references/.
    measureNoise(set, spec.file, info);
    std::ofstream note(fs::path(spec.file).replace_extension(".txt"));
    note << spec.what << " of " << s.name << "\nfile: " << spec.file.filename().string() << "\nmethod: " << spec.method
         << "\nkey: " << spec.key;
    if (!base.empty())
        note << "\nextends: " << firstFile.filename().string() << " (its " << kReferenceChunks
             << " chunks per half as stored, halves sha256 " << base << ", then chunks " << kReferenceChunks + 1 << "-"
             << spec.chunks << ")";
    note << "\ncommit: " << gitCommit() << "\nseconds: " << info.seconds
         << (base.empty() ? "" : " (both stages)")
         << "\nnoise (RMSE of the mean, from the halves): " << info.noiseRmse
         << "\nnoise relative RMSE: " << info.noiseRelativeRmse << "\n";
    return set;
}

// A scene's reference (the mean of its two halves), loaded or rendered
// (referenceSet, which puts its noise in `info`). `extend`: a part (d) reference the
// scene asks more chunks of than are stored is extended (--references); without
// it, the stored kReferenceChunks-chunk reference is used and the summary says so
// (a report run never spends hours on a reference that exists).
Image referenceImage(const BenchmarkScene& s, const Scene& scene, ReferencePart part, const fs::path& dir,
                     const Log& log, ReferenceInfo& info, double minutes, bool extend) {
    const int wanted = referenceChunks(s, part);
    ReferenceSpec spec = referenceSpec(s, part, dir, wanted);
    if (!extend && wanted > kReferenceChunks && !fs::exists(spec.file))
        spec = referenceSpec(s, part, dir, kReferenceChunks);
    const ImageSet set = referenceSet(s, scene, part, spec, dir, log, info, minutes);
    if (info.incomplete) return Image();
    info.wantedChunks = wanted;
    if (info.chunks < wanted)
        log.line("%s: %s has %d of the %d chunks per half asked for (%s extends it)", s.name.c_str(),
                 spec.what.c_str(), info.chunks, wanted, extendCommand(s.name, wanted).c_str());
    return set.image;
}

// The part (d) reference against an independent estimate of the same quantity
// by another method: stochastic VRL Lightcuts (K = 32) averaged over `sets`
// renders, each from its own VRL set (also unbiased for the true transport).
// Their difference's RMSE (on luminance) is compared with what their two noises
// predict, sqrt(noise_ref^2 + noise_check^2), the check's noise from the spread
// of its renders.
struct ReferenceCheck {
    int sets = 0, spp = 0;
    uint64_t vrls = 0;
    double differenceRmse = 0.0, expectedRmse = 0.0, seconds = 0.0;
    double checkNoiseRmse = 0.0;  // of the check's mean
    bool cached = false;  // read from beside the reference (seconds then as recorded)
    std::string commit;   // the code that computed it
    bool done() const { return sets > 0; }
};

// The check's settings: its VRL sets, VRLs per set, samples per pixel, cut size
// and the seed of set 0 (set k: + k). A stored check is keyed by all of them.
constexpr int kCheckSets = 16, kCheckSpp = 8;
constexpr uint64_t kCheckVrls = 10000, kCheckSeedBase = 3000017;
constexpr uint32_t kCheckCutSize = 32;

ReferenceCheck checkPartReference(const BenchmarkScene& s, const Scene& scene, const Image& reference,
                                  const ReferenceInfo& info, const Log& log) {
    const int sets = kCheckSets;
    ReferenceCheck c;
    c.sets = sets, c.vrls = kCheckVrls, c.spp = kCheckSpp;
    c.commit = gitCommit();
    const auto start = Clock::now();
    const size_t n = size_t(s.width) * size_t(s.height);
    std::vector<double> sum(n, 0.0), sum2(n, 0.0);
    for (int k = 0; k < sets; ++k) {
        RenderSettings settings =
            settingsFor(s, MethodRun{RenderMethod::VrlStochastic, kCheckVrls, kCheckSpp, 0.02f, kCheckCutSize},
                        kCheckSeedBase + uint64_t(k));
        settings.transports = TransportSelection::parse("multiple");
        const Image image = render(scene, settings).image;
        for (size_t i = 0; i < n; ++i) {
            const double y = luminance(image[i]);
            sum[i] += y, sum2[i] += y * y;
        }
    }
    double difference2 = 0.0, variance = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double mean = sum[i] / sets;
        variance += std::max(0.0, sum2[i] / sets - mean * mean) / (sets - 1);  // of the mean
        const double d = mean - double(luminance(reference[i]));
        difference2 += d * d;
    }
    c.differenceRmse = std::sqrt(difference2 / double(n));
    c.checkNoiseRmse = std::sqrt(variance / double(n));
    c.expectedRmse = std::sqrt(info.noiseRmse * info.noiseRmse + variance / double(n));
    c.seconds = secondsSince(start);
    log.line("%s: part (d) reference check: stochastic VRL Lightcuts K=%u over %d sets of %llu: RMSE of the difference %.4g, expected "
             "from the noises %.4g (ratio %.2f)", s.name.c_str(), kCheckCutSize, sets, (unsigned long long)kCheckVrls, c.differenceRmse,
             c.expectedRmse, c.differenceRmse / c.expectedRmse);
    return c;
}

// The check of a stored part (d) reference, kept beside it as the reference is
// (<reference>.check.txt, named by its file, keyed by that file and the check's
// settings): computed once, by --references or by the first report run that finds
// none, then read (the check is of the reference, which a report run only reads;
// it took 2.5 min of the full report). A file of other settings, or one that does
// not parse, is said so and replaced.
ReferenceCheck storedPartReferenceCheck(const BenchmarkScene& s, const Scene& scene, const Image& reference,
                                        const ReferenceInfo& info, const Log& log) {
    const fs::path file = fs::path(info.file).replace_extension(".check.txt");
    const std::string key = "stochastic VRL Lightcuts K=" + std::to_string(kCheckCutSize) + " sets=" +
                            std::to_string(kCheckSets) + " vrls=" + std::to_string(kCheckVrls) + " spp=" +
                            std::to_string(kCheckSpp) + " seeds=" + std::to_string(kCheckSeedBase) +
                            "+set version=" + VRL_VERSION + " reference=" + info.file.filename().string();
    if (fs::exists(file)) {
        std::ifstream in(file);
        std::map<std::string, std::string> fields;
        for (std::string line; std::getline(in, line);) {
            if (!line.empty() && line.back() == '\r') line.pop_back();  // a CRLF checkout
            if (const size_t colon = line.find(": "); colon != std::string::npos)
                fields[line.substr(0, colon)] = line.substr(colon + 2);
        }
        ReferenceCheck c;
        c.sets = kCheckSets, c.vrls = kCheckVrls, c.spp = kCheckSpp, c.cached = true;
        c.commit = fields["commit"].empty() ? "unknown" : fields["commit"];
        const auto number = [&](const char* name, double& value) {
            try {
                size_t used = 0;
                value = std::stod(fields.at(name), &used);
                return used == fields.at(name).size() && std::isfinite(value) && value > 0.0;
            } catch (const std::exception&) {
                return false;
            }
        };
        if (fields["key"] != key)
            log.line("%s: %s is of other settings (key '%s', expected '%s'): computing the check again",
                     s.name.c_str(), file.filename().c_str(), fields["key"].c_str(), key.c_str());
        else if (!number("difference RMSE", c.differenceRmse) || !number("expected RMSE", c.expectedRmse) ||
                 !number("check noise RMSE", c.checkNoiseRmse) || !number("seconds", c.seconds))
            log.line("%s: %s lacks a positive number or does not parse: computing the check again", s.name.c_str(),
                     file.filename().c_str());
        else {
            log.line("%s: part (d) reference check from the cache (%s): RMSE of the difference %.4g, expected from the "
                     "noises %.4g (ratio %.2f)", s.name.c_str(), file.filename().c_str(), c.differenceRmse,
                     c.expectedRmse, c.differenceRmse / c.expectedRmse);
            return c;
        }
    }
    const ReferenceCheck c = checkPartReference(s, scene, reference, info, log);
    std::ostringstream text;
    text << std::setprecision(17) << "part (d) reference check of " << info.file.filename().string()
         << "\nkey: " << key << "\ncommit: " << c.commit << "\nseconds: " << c.seconds
         << "\ndifference RMSE: " << c.differenceRmse << "\nexpected RMSE: " << c.expectedRmse
         << "\ncheck noise RMSE: " << c.checkNoiseRmse << "\n";
    util::writeFileAtomically(file, text.str());
    return c;
}

// Figure 4: seconds per pixel of brute force (plain VRLs / VPLs) and of
// Lightcuts, multiple scattering (d) only, on a fixed spread of pixels.
std::vector<SpeedupResult> measureSpeedup(const BenchmarkScene& s, const Scene& scene, const Log& log) {
    std::vector<SpeedupResult> results;
    for (const bool points : {false, true}) {
        for (const uint64_t n : s.speedupLights) {
            RenderSettings plain = settingsFor(s, MethodRun{points ? RenderMethod::Vpl : RenderMethod::Vrl, n, 1}, 7);
            plain.transports = TransportSelection::parse("multiple");
            RenderSettings cuts = plain;
            cuts.method = points ? RenderMethod::VplLightcuts : RenderMethod::VrlLightcuts;
            RenderLights plainLights = prepareLights(scene, plain);
            RenderLights cutLights;
            cutLights.tree = LightTree::build(plainLights.vrls.vrls, LightTreeSettings{cuts.partitionSize, cuts.seed, points});
            // Brute force costs N (VRLs) or 32 N (VPLs) terms per pixel: keep it to ~3e7 terms,
            // with at least 8 pixels for the VRLs (their error feeds the stochastic cut's
            // samples) and 2 for the VPLs (10^7 VPLs: 3.2e8 terms a pixel).
            const double terms = double(plainLights.vrls.vrls.size()) * (points ? 32.0 : 1.0);
            const int pixels = int(std::clamp(3e7 / std::max(1.0, terms), points ? 2.0 : 8.0, 2048.0));
            std::vector<TileRect> tiles;
            const int total = s.width * s.height;
            for (int k = 0; k < pixels; ++k) {
                const long long index = (long long)k * total / pixels;
                const int x = int(index % s.width), y = int(index / s.width);
                tiles.push_back({x, y, x + 1, y + 1});
            }
            const auto timeShader = [&](const TileShader& shader, double minimumSeconds, double* eval, double* inter,
                                        std::vector<float>* values) {
                int repeats = 0;
                double evalSum = 0.0, interSum = 0.0;
                const auto start = Clock::now();
                do {
                    std::vector<TileImages> out(tiles.size());
                    tbb::parallel_for(size_t(0), tiles.size(), [&](size_t t) { out[t] = shader.renderTile(tiles[t]); });
                    if (values && repeats == 0) {  // each pixel's luminance (the tiles are single pixels)
                        values->clear();
                        for (const auto& o : out) values->push_back(luminance(o.layers[0][0]));
                    }
                    ++repeats;
                    if (eval && out[0].layers.size() >= 4) {
                        const size_t layers = out[0].layers.size();
                        for (const auto& o : out) evalSum += o.layers[layers - 3][0].x, interSum += o.layers[layers - 2][0].x;
                    }
                } while (secondsSince(start) < minimumSeconds);
                if (eval) *eval = evalSum / double(repeats * tiles.size());
                if (inter) *inter = interSum / double(repeats * tiles.size());
                return secondsSince(start) / double(repeats * tiles.size());
            };
            SpeedupResult r;
            r.scene = s.name;
            r.kind = points ? "VPL" : "VRL";
            r.lights = plainLights.vrls.vrls.size();
            std::vector<float> bruteValues, cutValues;
            r.bruteSecondsPerPixel =
                timeShader(TileShader(scene, plain, plainLights), 0.0, nullptr, nullptr, &bruteValues);
            r.lightcutsSecondsPerPixel =
                timeShader(TileShader(scene, cuts, cutLights), 0.5, &r.meanEval, &r.meanInter, &cutValues);
            r.error = relativeRmse(cutValues, bruteValues);
            log.line("%s: speed-up %s N=%llu: brute %.3g s/pixel, Lightcuts %.3g s/pixel -> %.1fx (%d pixels, "
                     "rel. RMSE %.3g)",
                     s.name.c_str(), r.kind.c_str(), (unsigned long long)r.lights, r.bruteSecondsPerPixel,
                     r.lightcutsSecondsPerPixel, r.bruteSecondsPerPixel / r.lightcutsSecondsPerPixel, pixels, r.error);
            results.push_back(r);
            if (points) continue;
            // Stochastic VRL Lightcuts (K = 32) at the deterministic cut's error: from 16
            // one-sample passes with their own seeds, the samples per pixel n it needs
            // for a relative RMSE (against plain VRLs over the same set, which it
            // estimates without bias) equal to the cut's, n = its relative variance per
            // sample / error^2 (at least 1), and its time n x the time per sample.
            RenderSettings stochastic = plain;
            stochastic.method = RenderMethod::VrlStochastic;
            stochastic.cut.stochasticCutSize = 32;
            constexpr int kPasses = 16;
            std::vector<double> sum(tiles.size(), 0.0), sum2(tiles.size(), 0.0);
            double perSample = 0.0;
            for (int p = 0; p < kPasses; ++p) {
                stochastic.seed = 100 + uint64_t(p);
                std::vector<float> values;
                perSample += timeShader(TileShader(scene, stochastic, cutLights), 0.0, nullptr, nullptr, &values) /
                             kPasses;
                for (size_t k = 0; k < values.size(); ++k) sum[k] += values[k], sum2[k] += double(values[k]) * values[k];
            }
            // Its expected relative MSE per sample, weighted as the metric weighs each pixel.
            double relativeVariance = 0.0;
            for (size_t k = 0; k < tiles.size(); ++k) {
                const double mean = sum[k] / kPasses, reference = bruteValues[k];
                relativeVariance += std::max(0.0, sum2[k] / kPasses - mean * mean) * kPasses / (kPasses - 1) /
                                    (reference * reference + kMetricEpsilon);
            }
            relativeVariance /= double(tiles.size());
            SpeedupResult st = r;
            st.kind = "VRL-stochastic";
            const double samples = r.error > 0.0 ? relativeVariance / (r.error * r.error) : NAN;
            st.lightcutsSecondsPerPixel = std::isfinite(samples) ? perSample * std::max(1.0, samples) : NAN;
            st.meanEval = 32.0, st.meanInter = 0.0;
            st.error = r.error;
            log.line("%s: speed-up stochastic K=32 N=%llu: %.3g s/pixel per sample, %.3g samples for rel. RMSE %.3g "
                     "-> %.1fx", s.name.c_str(), (unsigned long long)r.lights, perSample, samples, r.error,
                     st.bruteSecondsPerPixel / st.lightcutsSecondsPerPixel);
            results.push_back(st);
        }
    }
    return results;
}

const Image* layerOf(const ImageSet& set, const std::string& name) {
    for (const auto& [n, image] : set.layers)
        if (n == name) return &image;
    return nullptr;
}

std::string fmt(double v, int precision = 3) {
    if (!std::isfinite(v)) return "—";
    std::ostringstream s;
    s << std::setprecision(precision) << v;
    return s.str();
}

std::string safeName(std::string s) {
    for (char& c : s)
        if (!std::isalnum((unsigned char)c) && c != '-' && c != '_') c = '_';
    return s;
}

std::string methodTitle(RenderMethod m) { return std::string(methodTraits(m).title); }

// The curves (MethodRun::curve()) a scene measured on one part, in run order.
std::vector<std::string> curvesMeasured(const std::vector<RunResult>& results, const std::string& scene,
                                        bool multipleOnly) {
    std::vector<std::string> curves;
    for (const auto& r : results)
        if (r.scene == scene && r.run.multipleOnly == multipleOnly &&
            std::find(curves.begin(), curves.end(), r.run.curve()) == curves.end())
            curves.push_back(r.run.curve());
    return curves;
}

// The points of one curve (MethodRun::curve()) above the noise rule's floor.
std::vector<CurvePoint> curveOf(const std::vector<RunResult>& results, const std::string& scene,
                                const std::string& curve, bool smape) {
    std::vector<CurvePoint> points;
    for (const auto& r : results) {
        if (r.scene != scene || r.run.curve() != curve || r.belowNoise()) continue;
        points.push_back({r.seconds, smape ? r.metrics.smape : r.metrics.rmse});
    }
    return cleanCurve(points);
}

std::string curveTitle(std::string curve) {
    if (curve.rfind("(d) ", 0) == 0) return "(d) " + curveTitle(curve.substr(4));
    for (const RenderMethod m : kRenderMethods) {
        const std::string name(methodName(m));
        if (curve.rfind(name, 0) == 0 && (curve.size() == name.size() || curve[name.size()] == ' '))
            return methodTitle(m) + curve.substr(name.size());
    }
    return curve;
}

struct SceneReport {
    BenchmarkScene scene;
    ReferenceInfo reference, partReference;
    ReferenceCheck partCheck;  // the scene that checks its part (d) reference (BenchmarkScene::checkPartReference)
    double loadSeconds = 0.0;
    std::string skipped;  // reason, if skipped
    std::map<RenderMethod, std::pair<double, double>> tableStats;  // method -> (#Eval, #Inter)
    std::pair<double, double> surfaceStats{NAN, NAN};  // VRL Lightcuts' part (c): (#Eval, #Inter) per pixel
    std::vector<std::string> images;  // markdown image lines
};

// A ratio of the other method's value to VRL Lightcuts' (error at equal time, or
// time to equal error): the winner in bold (> 1: VRL Lightcuts, < 1: the other,
// marked so); '—' where the curves do not overlap.
std::string ratioCell(const std::optional<double>& other, double ours) {
    if (!other) return "—";
    const double ratio = *other / ours;
    return ratio >= 1.0 ? "**" + fmt(ratio) + "**" : fmt(ratio) + " (**other**)";
}

// The question a reader asks of each comparison: does VRL Lightcuts (e = 0.02) take
// at least 10x less time than plain VRLs at equal error, and reach a lower error
// than VPL Lightcuts at equal time? Answered from the measured curves (above the
// noise floor), with the figures that explain a "no". Each comparison is read both
// ways: at VRL Lightcuts' points (the other curve interpolated) and at the other
// method's points (VRL Lightcuts' curve interpolated), so that a curve of one or two
// points, inside the other's time range, is still compared.
std::string verdict(const std::vector<RunResult>& results, const std::string& name, bool multipleOnly) {
    const std::string prefix = multipleOnly ? "(d) " : "";
    const std::string ours = prefix + "vrl-lightcuts e=0.02";
    const auto plain = curveOf(results, name, prefix + "vrl", false);
    const auto vpl = curveOf(results, name, prefix + "vpl-lightcuts e=0.02", false);
    const auto recommended = curveOf(results, name, ours, false);
    std::optional<double> bestSpeedup;
    int vplMeasured = 0, vplBeaten = 0;
    std::string vplRatios, cost;
    const auto compareWithVpl = [&](double vplError, double ourError) {
        ++vplMeasured;
        vplBeaten += vplError > ourError;
        vplRatios += (vplRatios.empty() ? "" : ", ") + fmt(vplError / ourError);
    };
    for (const auto& r : results) {
        if (r.scene != name || r.run.curve() != ours || r.belowNoise()) continue;
        if (const auto t = timeToError(plain, r.metrics.rmse))
            bestSpeedup = std::max(bestSpeedup.value_or(0.0), *t / r.seconds);
        if (const auto e = errorAtTime(vpl, r.seconds)) compareWithVpl(*e, r.metrics.rmse);
        cost += (cost.empty() ? "" : ", ") + fmt(r.stats.meanEvaluated, 4) + " of N = " + std::to_string(r.run.lights);
    }
    for (const CurvePoint& p : plain)  // at plain VRLs' points
        if (const auto t = timeToError(recommended, p.error))
            bestSpeedup = std::max(bestSpeedup.value_or(0.0), p.seconds / *t);
    for (const CurvePoint& p : vpl)  // at VPL Lightcuts' points
        if (const auto e = errorAtTime(recommended, p.seconds)) compareWithVpl(p.error, *e);
    std::ostringstream v;
    v << "**Verdict" << (multipleOnly ? " for part (d)" : " for the whole image") << ".** ";
    if (!bestSpeedup) {
        v << "Against plain VRLs: not measurable (neither curve reaches an error within the other's measured range "
             "above the noise floor). ";
    } else if (*bestSpeedup >= 10.0) {
        v << "VRL Lightcuts reaches plain VRLs' error in at least 10× less time (up to " << fmt(*bestSpeedup) << "×). ";
    } else {
        v << "VRL Lightcuts does **not** reach 10× less time than plain VRLs at equal error: at most "
          << fmt(*bestSpeedup) << "×. Per pixel it evaluates #Eval = " << cost
          << " VRLs over its camera segments (plain VRLs evaluate all N on each)"
          << (multipleOnly ? "" : "; part (a) is sampled alike in both (path tracing, and the surface VPLs of broad lobes drawn by a "
                                 "small stochastic cut) and costs both the same time, and both take part (b)'s "
                                 "surface light from surface VPLs (plain VRLs from every VPL, VRL Lightcuts by a cut)")
          << ". ";
    }
    const bool vplRun = std::any_of(results.begin(), results.end(), [&](const RunResult& r) {
        return r.scene == name && r.run.curve() == prefix + "vpl-lightcuts e=0.02";
    });
    if (!vplRun)
        v << "VPL Lightcuts was not run on this part of this scene (left out to keep the full report within its "
             "45-minute limit), so there is no comparison with it here.";
    else if (vplMeasured == 0)
        v << "Against VPL Lightcuts at equal time: not measurable (neither curve has a point above the noise floor "
             "within the other's measured time range).";
    else if (vplBeaten == vplMeasured)
        v << "It has lower error than VPL Lightcuts at equal time at every point where both are measured (VPL's "
             "error × "
          << vplRatios << ", at VRL Lightcuts' points, then at VPL's).";
    else
        v << "It has lower error than VPL Lightcuts at equal time at " << vplBeaten << " of " << vplMeasured
          << " points where both are measured only (VPL's error × " << vplRatios
          << ", at VRL Lightcuts' points, then at VPL's).";
    return v.str();
}

// One part's comparison for a scene: its plot, every run's errors, and the ratios
// of VRL Lightcuts (e = 0.02) against each other method's curve.
void writeComparison(std::ostream& md, const std::vector<RunResult>& results, const std::string& name,
                     bool multipleOnly) {
    const std::string prefix = multipleOnly ? "(d) " : "";
    std::vector<std::string> others = {"vrl", "vrl-stochastic K=8", "vrl-stochastic K=32", "vpl-lightcuts e=0.02"};
    if (!multipleOnly) others.push_back("path");
    for (auto& o : others) o = prefix + o;
    const std::vector<std::string> measured = curvesMeasured(results, name, multipleOnly);
    std::erase_if(others, [&](const std::string& curve) {  // a curve this part does not measure
        return std::find(measured.begin(), measured.end(), curve) == measured.end();
    });
    const std::string recommended = prefix + "vrl-lightcuts e=0.02";
    md << "![error against time](error-time-" << safeName(name) << (multipleOnly ? "-d" : "") << ".png)\n\n";
    md << "| method | settings | time (s) | RMSE | RMSE / reference noise | rel. RMSE | SMAPE | mean ratio | #Eval | #Inter "
          "| renders: RMSE from, to |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : results) {
        if (r.scene != name || r.run.multipleOnly != multipleOnly) continue;
        const bool cuts = usesLightTree(r.run.method);
        md << "| " << methodTitle(r.run.method) << " | " << r.run.label() << " | " << fmt(r.seconds) << " | "
           << fmt(r.metrics.rmse) << " | " << fmt(r.metrics.rmse / r.referenceNoiseRmse) << (r.belowNoise() ? " ‡" : "")
           << " | " << fmt(r.metrics.relativeRmse) << " | " << fmt(r.metrics.smape) << " | "
           << fmt(r.metrics.meanReference > 0 ? r.metrics.meanTest / r.metrics.meanReference : NAN) << " | "
           << (cuts ? fmt(r.stats.meanEvaluated, 4) : "") << " | " << (cuts ? fmt(r.stats.meanIntersected, 4) : "")
           << " | "
           << (r.renders > 1 ? std::to_string(r.renders) + ": " + fmt(r.rmseMin) + ", " + fmt(r.rmseMax) : "1")
           << " |\n";
    }
    // The noise rule, said in words where it decides the comparison: a reference too
    // noisy for every run is a failed reference, not a result about the methods.
    int runs = 0, below = 0;
    double floor = 0.0;
    for (const auto& r : results) {
        if (r.scene != name || r.run.multipleOnly != multipleOnly) continue;
        ++runs;
        below += r.belowNoise();
        floor = kNoiseFactor * r.referenceNoiseRmse;
    }
    if (runs > 0 && below == runs)
        md << "\n**This comparison cannot decide:** every run's RMSE is below the noise rule's floor (" << fmt(floor)
           << ", " << fmt(kNoiseFactor) << "× the reference's own noise), so the reference fails the rule at this "
           << "resolution and no curve, ratio or verdict below says anything about the methods. It needs a better "
           << "reference, not more of these runs.\n";
    else if (below > 0)
        md << "\n" << below << " of " << runs << " runs are below the noise rule's floor (" << fmt(floor)
           << ") and are left out of the ratios.\n";
    md << "\nEqual-time error ratios (the other method's error at VRL Lightcuts' time, divided by VRL Lightcuts' "
          "error; > 1: VRL Lightcuts is better) and equal-error time ratios (the other method's time to reach VRL "
          "Lightcuts' RMSE, divided by VRL Lightcuts' time; > 1: VRL Lightcuts is faster); '—' where the other "
          "method's measured range (above the noise rule's floor) does not reach; ‡: below the noise rule's "
          "floor, no ratio.\n\n";
    md << "| VRL Lightcuts point | time (s) |";
    for (const auto& m : others) md << " " << curveTitle(m) << ": RMSE × | SMAPE × | time × |";
    md << "\n|---|---|";
    for (size_t k = 0; k < others.size(); ++k) md << "---|---|---|";
    md << "\n";
    for (const auto& r : results) {
        if (r.scene != name || r.run.curve() != recommended) continue;
        md << "| " << r.run.label() << (r.belowNoise() ? " ‡" : "") << " | " << fmt(r.seconds) << " |";
        if (r.belowNoise()) {  // the noise rule: no ratio
            for (size_t k = 0; k < others.size(); ++k) md << " ‡ | ‡ | ‡ |";
            md << "\n";
            continue;
        }
        for (const auto& m : others) {
            const auto rmseCurve = curveOf(results, name, m, false), smapeCurve = curveOf(results, name, m, true);
            const auto e1 = errorAtTime(rmseCurve, r.seconds), e2 = errorAtTime(smapeCurve, r.seconds);
            const auto t = timeToError(rmseCurve, r.metrics.rmse);
            md << " " << ratioCell(e1, r.metrics.rmse) << " | " << ratioCell(e2, r.metrics.smape) << " | "
               << ratioCell(t, r.seconds) << " |";
        }
        md << "\n";
    }
    // The same ratios read the other way: at each other method's point, VRL Lightcuts'
    // curve interpolated. A curve of few points inside VRL Lightcuts' time range
    // is compared here too, where the table above may have no ratio.
    const auto ourRmse = curveOf(results, name, recommended, false), ourSmape = curveOf(results, name, recommended, true);
    md << "\nThe same ratios at the other methods' points (VRL Lightcuts' curve interpolated at their time or error; "
          "> 1: VRL Lightcuts is better):\n\n| method | point | time (s) | RMSE × | SMAPE × | time × |\n"
          "|---|---|---|---|---|---|\n";
    for (const auto& m : others)
        for (const auto& r : results) {
            if (r.scene != name || r.run.curve() != m) continue;
            md << "| " << curveTitle(m) << " | " << r.run.label() << (r.belowNoise() ? " ‡" : "") << " | "
               << fmt(r.seconds) << " |";
            if (r.belowNoise()) {
                md << " ‡ | ‡ | ‡ |\n";
                continue;
            }
            const auto e1 = errorAtTime(ourRmse, r.seconds), e2 = errorAtTime(ourSmape, r.seconds);
            const auto t = timeToError(ourRmse, r.metrics.rmse);
            const auto cell = [](const std::optional<double>& oursValue, double other) {
                return oursValue ? ratioCell(other, *oursValue) : std::string("—");
            };
            md << " " << cell(e1, r.metrics.rmse) << " | " << cell(e2, r.metrics.smape) << " | "
               << cell(t, r.seconds) << " |\n";
        }
    md << "\n" << verdict(results, name, multipleOnly) << "\n\n";
}

// "What to use when", from the measured curves: for each scene and part, at a
// few time budgets, the method (curve) with the lowest RMSE at that time among
// those whose measured range (above the noise rule's floor) holds it, with the
// runner-up's error as a multiple of the winner's; then, per method, where it won.
void writeWhatToUseWhen(std::ostream& md, const std::vector<RunResult>& results,
                        const std::vector<SceneReport>& scenes) {
    // Budgets 0.1, 0.3, 1, 3, ... 300 s; the columns shown are those where some row has a winner.
    const std::vector<double> budgets = {0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 300.0};
    struct Row {
        std::string scene, part;
        std::vector<std::string> cells;  // per budget; empty: no winner
    };
    std::vector<Row> rows;
    std::vector<bool> shown(budgets.size(), false);
    std::map<std::string, std::vector<std::string>> wins;  // method -> "scene part at t"
    int cells = 0;
    for (const auto& s : scenes) {
        if (!s.skipped.empty()) continue;
        for (const bool multipleOnly : {false, true}) {
            const std::vector<std::string> curves = curvesMeasured(results, s.scene.name, multipleOnly);
            if (curves.empty()) continue;
            const auto title = [&](const std::string& curve) {  // without the part's "(d) "
                return curveTitle(multipleOnly ? curve.substr(4) : curve);
            };
            Row row{s.scene.name, multipleOnly ? "(d) alone" : "whole image", {}};
            for (size_t b = 0; b < budgets.size(); ++b) {
                std::vector<std::pair<double, std::string>> at;  // (RMSE at the budget, curve)
                for (const auto& c : curves)
                    if (const auto e = errorAtTime(curveOf(results, s.scene.name, c, false), budgets[b]))
                        at.push_back({*e, c});
                if (at.size() < 2) {
                    row.cells.emplace_back();
                    continue;
                }
                std::sort(at.begin(), at.end());
                const std::string winner = title(at[0].second);
                row.cells.push_back("**" + winner + "** (" + fmt(at[0].first) + "; " + title(at[1].second) + " ×" +
                                    fmt(at[1].first / at[0].first) + ")");
                wins[winner].push_back(row.scene + " " + row.part + " at " + fmt(budgets[b]) + " s");
                shown[b] = true;
                ++cells;
            }
            rows.push_back(std::move(row));
        }
    }
    md << "## What to use when\n\nFrom the curves above: at each time budget, the method with the lowest RMSE at "
          "that time (interpolated between its measured points, never extrapolated; runs below the noise rule's "
          "floor left out), and the runner-up's RMSE as a multiple of the winner's; '—': fewer than two methods "
          "were measured at that time. A method's curve is one setting (threshold e or cut size K) over N and spp, "
          "so the table also says which setting to use.\n\n";
    if (cells == 0) {
        md << "No time budget had two methods measured above the noise floor.\n\n";
        return;
    }
    md << "| scene | part |";
    for (size_t b = 0; b < budgets.size(); ++b)
        if (shown[b]) md << " at " << fmt(budgets[b]) << " s |";
    md << "\n|---|---|";
    for (size_t b = 0; b < budgets.size(); ++b)
        if (shown[b]) md << "---|";
    md << "\n";
    for (const auto& row : rows) {
        md << "| " << row.scene << " | " << row.part << " |";
        for (size_t b = 0; b < budgets.size(); ++b)
            if (shown[b]) md << " " << (row.cells[b].empty() ? "—" : row.cells[b]) << " |";
        md << "\n";
    }
    md << "\n";
    for (const auto& [method, where] : wins) {
        md << "- **" << method << "** has the lowest error in " << where.size() << " of " << cells << " cells: ";
        for (size_t k = 0; k < where.size(); ++k) md << (k ? ", " : "") << where[k];
        md << ".\n";
    }
    md << "\n";
}

void writeSummary(const fs::path& path, const Options& o, const std::vector<SceneReport>& scenes,
                  const std::vector<RunResult>& results, const std::vector<SpeedupResult>& speedups,
                  double totalSeconds, int threads) {
    std::ofstream md(path);
    const std::time_t now = std::time(nullptr);
    char date[64];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    md << "# Error against run time: VRL Lightcuts, stochastic VRL Lightcuts, plain VRLs, VPL Lightcuts and path "
          "tracing\n\n";
    std::string options = o.quick ? " --quick" : "";
    if (!o.only.empty()) {
        options += " --scenes ";
        for (size_t i = 0; i < o.only.size(); ++i) options += (i ? "," : "") + o.only[i];
    }
    if (o.partReferenceChunks > 0) options += " --part-reference-chunks " + std::to_string(o.partReferenceChunks);
    md << "Generated by `build/bench/vrl_report" << options << "` on " << date << " with " << threads
       << " threads, vrlcuts " << VRL_VERSION << "; the whole report took " << fmt(totalSeconds / 60.0, 3)
       << " minutes. Data: `results.csv`, `speedup.csv`.\n\n";
    md << "Every image is compared with its reference: the whole image with the path tracer's (on a scene lit "
          "through glass, light tracing connected to the camera plus the path tracer where the camera sees the "
          "glass: the scene table says which), part (d) alone with "
          "plain VRLs averaged over many independent VRL sets (each reference two independent halves; the noise "
          "columns are its own estimated error, RMSE(half1, half2) / 2, below which no method can be measured). "
          "Times are wall-clock seconds of light tracing, tree build and shading; the scene load is common to all "
          "methods and left out. The VRL methods render parts (a) and (b) by path sampling at the stated spp (their "
          "noise is part of the whole image's error, and the spp grow with N along each curve) and parts (c) and (d) "
          "with their VRLs: plain VRLs and VRL Lightcuts (relative error threshold e, 0.02 unless stated) once per "
          "pixel, with part (b)'s non-Dirac surface light from surface VPLs of the same light paths (every VPL or a "
          "cut, once per pixel) and part (a)'s light of broad lobes from the same VPLs (two drawn by a stochastic "
          "cut per sample), stochastic VRL Lightcuts at every sample (K VRLs per camera segment and surface "
          "point). VPL "
          "Lightcuts path-samples part (c) too and gathers (d) without clamping, as in the paper, at "
       << kDefaultVplDistanceSamples
       << " stratified distance samples per camera segment, or D where a label says D=... (fewer: cheaper and noisier; "
          "`results.csv`: distance_samples; `vrl render --distance-samples`). Errors are on luminance; SMAPE uses epsilon 0.01. "
          "Rays pass through pixel centres; maximum path length 12.\n\n"
          "**Noise rule.** A run whose RMSE is below " << fmt(kNoiseFactor) << "× the reference's own estimated RMSE "
          "cannot be told from the reference's noise: it is marked ‡ in the tables, written with below_noise = 1 in "
          "`results.csv`, and left out of every ratio (its curve then ends before it).\n\n"
          "**Points of several renders.** One render's error moves with its seed, most at the cheapest settings, "
          "so those are rendered more than once, each render from its own seed (the renders column says how many "
          "and the range of their RMSEs; `results.csv`: renders, rmse_min, rmse_max). Such a point's time is the "
          "renders' mean, its RMSE and relative RMSE their root-mean-square (the root of an estimate of the expected "
          "squared error, which an unbiased method's time buys down), its SMAPE their mean; the images and cut statistics are the first "
          "render's. The vertical bars on the RMSE plots are those ranges. A point's \"mean ratio\" is its renders' "
          "mean. One render's RMSE is on average a little below the root of its expected squared error (the "
          "square root is concave), so a point of one render sits a little low beside one of three.\n\n";
    md << "## Scenes\n\n| scene | description | resolution | reference (whole image) | its noise RMSE / rel. RMSE / "
          "SMAPE | part (d) reference | its noise RMSE / rel. RMSE / SMAPE |\n|---|---|---|---|---|---|---|\n";
    for (const auto& s : scenes) {
        if (!s.skipped.empty()) {
            md << "| " << s.scene.name << " | " << s.scene.description << " | skipped: " << s.skipped << " | | | | |\n";
            continue;
        }
        md << "| " << s.scene.name << " | " << s.scene.description << (s.scene.medium.empty() ? "" : " (`--medium " + s.scene.medium + "`)")
           << " | " << s.scene.width << "x" << s.scene.height << " | ";
        if (s.reference.spp > 0)
            md << s.reference.method << ", " << fmt(s.reference.seconds, 4) << " s"
               << (s.reference.cached ? " (cached)" : "") << " | " << fmt(s.reference.noiseRmse) << " / "
               << fmt(s.reference.noiseRelativeRmse) << " / " << fmt(s.reference.noiseSmape) << " | ";
        else
            md << "none (part (d) alone) | | ";
        md << s.partReference.method << ", " << fmt(s.partReference.seconds, 4) << " s"
           << (s.partReference.cached ? " (cached)" : "");
        if (s.partReference.wantedChunks > s.partReference.chunks)
            md << " (short: " << 2 * s.partReference.wantedChunks * s.scene.partReferenceSets
               << " sets are asked for; `" << extendCommand(s.scene.name, s.partReference.wantedChunks)
               << "` extends it)";
        md << " | " << fmt(s.partReference.noiseRmse) << " / "
           << fmt(s.partReference.noiseRelativeRmse) << " / " << fmt(s.partReference.noiseSmape) << " |\n";
    }
    md << "\n";
    for (const auto& s : scenes) {
        if (!s.partCheck.done()) continue;
        const ReferenceCheck& c = s.partCheck;
        const double ratio = c.differenceRmse / c.expectedRmse;
        md << "**Part (d) reference check** (" << s.scene.name << "): the part (d) reference (plain VRLs over "
           << "independent VRL sets) against another method, stochastic VRL Lightcuts (K = 32) averaged over " << c.sets
           << " renders of " << c.spp << " spp, each from its own set of " << c.vrls << " VRLs (both estimate the "
           << "true transport without bias): RMSE of their difference " << fmt(c.differenceRmse) << ", expected from "
           << "their two noises " << fmt(c.expectedRmse) << " (ratio " << fmt(ratio) << "; "
           << (ratio < 1.5 ? "they agree within their noise" : "**they do not agree within their noise**")
           << "). Cost of a noise (time × noise², lower is better): the reference "
           << fmt(s.partReference.seconds * s.partReference.noiseRmse * s.partReference.noiseRmse) << " ("
           << fmt(s.partReference.seconds) << " s, noise " << fmt(s.partReference.noiseRmse)
           << (s.partReference.cached ? ", time as recorded in the cache" : "") << "), stochastic VRL Lightcuts over "
           << "sets " << fmt(c.seconds * c.checkNoiseRmse * c.checkNoiseRmse) << " (" << fmt(c.seconds)
           << " s, noise " << fmt(c.checkNoiseRmse) << ")."
           << (c.cached ? " The check is stored beside the reference (computed by commit " + c.commit +
                              "; its time as recorded there)."
                        : "")
           << "\n\n";
    }
    for (const auto& s : scenes) {
        if (!s.skipped.empty()) continue;
        const std::string& name = s.scene.name;
        md << "## " << name << "\n\n";
        if (std::any_of(results.begin(), results.end(),
                        [&](const RunResult& r) { return r.scene == name && !r.run.multipleOnly; })) {
            md << "### The whole image\n\n";
            writeComparison(md, results, name, false);
        }
        md << "### Part (d) alone (multiple scattering: the paper's Figure 3 comparison)\n\n"
           << "Against the part (d) reference; parts (a)-(c) are off, so only the virtual lights' own error counts. "
              "Plain VRLs, VRL and VPL Lightcuts at 1 spp (rays through pixel centres: more samples only redraw the "
              "estimators' numbers); stochastic VRL Lightcuts draw new cuts per sample. The path tracer cannot be "
              "restricted to (d) here.\n\n";
        writeComparison(md, results, name, true);
        for (const auto& line : s.images) md << line << "\n";
        md << "\n";
    }
    writeWhatToUseWhen(md, results, scenes);
    md << "## Table 1: mean #Eval and #Inter per pixel (default threshold, the N stated)\n\n";
    md << "| scene | N | VPL Lightcuts #Eval | #Inter | VRL Lightcuts #Eval | #Inter | VRL Lightcuts, part (c): #Eval | "
          "#Inter |\n|---|---|---|---|---|---|---|---|\n";
    for (const auto& s : scenes) {
        if (!s.skipped.empty()) continue;
        const auto get = [&](RenderMethod m) {
            const auto it = s.tableStats.find(m);
            return it == s.tableStats.end() ? std::pair<double, double>(NAN, NAN) : it->second;
        };
        const auto vpl = get(RenderMethod::VplLightcuts), vrlc = get(RenderMethod::VrlLightcuts);
        md << "| " << s.scene.name << " | " << s.scene.tableLights << " | " << fmt(vpl.first, 4) << " | "
           << fmt(vpl.second, 4) << " | " << fmt(vrlc.first, 4) << " | " << fmt(vrlc.second, 4) << " | "
           << fmt(s.surfaceStats.first, 4) << " | " << fmt(s.surfaceStats.second, 4) << " |\n";
    }
    md << "\nVPL counts are summed over the " << kDefaultVplDistanceSamples
       << " distance samples of each camera segment (one cut each); VRL counts "
          "are one cut per camera segment; part (c), VRL-lit surfaces, one cut per surface point (VPL Lightcuts "
          "path-sample it).\n\n";
    md << "## Figure 4: speed-up of Lightcuts over brute force\n\n![speed-up](speedup.png)\n\n";
    md << "Multiple scattering (d) only, seconds per pixel on a fixed spread of pixels (brute force: plain VRLs, or "
          "every VPL at each distance sample), at a fixed error: the deterministic cut's (threshold 0.02) relative "
          "RMSE against brute force on those pixels, which VRL-stochastic (K = 32) is given the samples per pixel "
          "to match (from the variance of 16 one-sample passes; its time is those samples' time).\n\n"
          "| scene | lights | N | brute force (ms/pixel) | cut (ms/pixel) | speed-up | rel. RMSE vs brute force | "
          "#Eval | #Inter |\n|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : speedups)
        md << "| " << r.scene << " | " << r.kind << " | " << r.lights << " | " << fmt(1e3 * r.bruteSecondsPerPixel)
           << " | " << fmt(1e3 * r.lightcutsSecondsPerPixel) << " | "
           << fmt(r.bruteSecondsPerPixel / r.lightcutsSecondsPerPixel) << " | " << fmt(r.error) << " | "
           << fmt(r.meanEval, 4) << " | " << fmt(r.meanInter, 4) << " |\n";
}

int runReport(const Options& o) {
    const auto start = Clock::now();
    const Log log(start);
    const int threads = o.threads > 0 ? o.threads : tbb::info::default_concurrency();
    tbb::task_arena arena(threads);
    if (!o.buildReferences || o.quick) fs::create_directories(o.out / "images");  // --references writes only references
    std::vector<BenchmarkScene> list = benchmarkScenes(o.quick, VRL_SOURCE_DIR, o.shared);
    if (!o.only.empty()) {
        std::erase_if(list, [&](const BenchmarkScene& s) { return std::find(o.only.begin(), o.only.end(), s.name) == o.only.end(); });
        if (list.empty()) throw std::invalid_argument("--scenes names no benchmark scene");
    }
    if (o.partReferenceChunks > 0)
        for (auto& s : list) s.partReferenceChunks = o.partReferenceChunks;
    log.line("report: %zu scenes, %d threads, output in %s%s", list.size(), threads, o.out.string().c_str(),
             o.quick ? " (quick)" : "");
    std::vector<SceneReport> scenes;
    std::vector<RunResult> results;
    std::vector<SpeedupResult> speedups;
    size_t totalRuns = 0, done = 0;
    for (const auto& s : list) totalRuns += s.runs.size();
    for (const auto& s : list) {
        SceneReport report;
        report.scene = s;
        if (!fs::exists(s.file)) {
            report.skipped = "no " + s.file.string() + (s.shared ? " (the shared scene folder is absent; --shared DIR)" : "");
            log.line("%s: skipped: %s", s.name.c_str(), report.skipped.c_str());
            done += s.runs.size();
            scenes.push_back(report);
            continue;
        }
        const auto loadStart = Clock::now();
        const auto scene = loadScene(s);
        report.loadSeconds = secondsSince(loadStart);
        arena.execute([&] {
            const fs::path referenceDir = o.quick ? o.out / "cache" : o.references;
            const double minutes = o.buildReferences ? o.referenceMinutes : 0.0;
            const auto referenceStart = Clock::now();
            // A scene measured on part (d) alone needs no whole-image reference.
            const bool wholeImage =
                std::any_of(s.runs.begin(), s.runs.end(), [](const MethodRun& r) { return !r.multipleOnly; });
            const Image reference =
                wholeImage ? referenceImage(s, *scene, ReferencePart::Image, referenceDir, log, report.reference, minutes,
                                            o.buildReferences)
                           : Image();
            const double left = minutes > 0.0 ? std::max(1e-9, minutes - secondsSince(referenceStart) / 60.0) : 0.0;
            const Image partReference =
                referenceImage(s, *scene, ReferencePart::Multiple, referenceDir, log, report.partReference, left,
                               o.buildReferences);
            // The part (d) reference against another method's estimate, on one scene.
            if (s.checkPartReference && !report.partReference.incomplete)
                report.partCheck = storedPartReferenceCheck(s, *scene, partReference, report.partReference, log);
            if (o.buildReferences) return;
            // The previews show the whole image, or part (d) where that is all a scene measures.
            const Image& shown = wholeImage ? reference : partReference;
            const float exposure = autoExposure(shown);
            writePreviewPng(shown, o.out / "images" / (safeName(s.name) + "-reference.png"), exposure);
            report.images.push_back(std::string(wholeImage ? "Reference" : "Part (d): its reference") +
                                    " and the largest setting of each method (same exposure):\n");
            std::string row = "| reference |", header = "|---|";
            std::string imageRow = "| ![](images/" + safeName(s.name) + "-reference.png) |";
            std::map<std::string, ImageSet> lastOfMethod;
            std::map<std::string, std::string> lastLabel;
            for (const auto& run : s.runs) {
                ++done;
                // The point's renders, each from its own seed; the first one's image and
                // statistics are what the previews and Table 1 show.
                const Image& against = run.multipleOnly ? partReference : reference;
                RenderStatistics stats;
                ImageSet images;
                std::vector<std::pair<double, ImageErrorMetrics>> renders;
                for (int repeat = 0; repeat < run.repeats; ++repeat) {
                    RenderStatistics repeatStats;
                    const auto runStart = Clock::now();
                    ImageSet repeatImages = render(*scene, runSettings(s, run, repeat), {}, &repeatStats);
                    renders.emplace_back(secondsSince(runStart), compareImages(against, repeatImages.image));
                    if (repeat == 0) images = std::move(repeatImages), stats = repeatStats;
                }
                RunResult r{s.name, run, 0.0, {}, stats,
                            run.multipleOnly ? report.partReference.noiseRmse : report.reference.noiseRmse};
                combineRenders(r, renders);
                const std::string spread = r.renders > 1 ? " (" + std::to_string(r.renders) + " renders, RMSE " +
                                                               fmt(r.rmseMin, 4) + " to " + fmt(r.rmseMax, 4) + ")"
                                                         : std::string();
                log.line("%s (%zu/%zu): %-13s %-22s %8.2f s  RMSE %.4g  rel %.4g  SMAPE %.4g%s%s%s", s.name.c_str(),
                         done, totalRuns, std::string(methodName(run.method)).c_str(), run.label().c_str(), r.seconds,
                         r.metrics.rmse, r.metrics.relativeRmse, r.metrics.smape, spread.c_str(),
                         r.belowNoise() ? "  (below the reference's noise)" : "",
                         r.metrics.nonFinitePixels ? "  (NON-FINITE PIXELS)" : "");
                // Table 1 and Figure 6: part (d)'s cuts from the (d)-alone runs, part (c)'s
                // from the whole image's, both Lightcuts at the default threshold and N.
                const bool tableRun = (run.method == RenderMethod::VrlLightcuts ||
                                       run.method == RenderMethod::VplLightcuts) &&
                                      run.lights == s.tableLights && run.errorThreshold == 0.02f &&
                                      run.distanceSamples == 0;
                if (tableRun && run.multipleOnly) {
                    report.tableStats[run.method] = {stats.meanEvaluated, stats.meanIntersected};
                    for (const char* counter : {"eval", "inter"})
                        if (const Image* layer = layerOf(images, counter))
                            lastOfMethod[std::string(methodName(run.method)) + "/" + counter] = ImageSet{*layer, {}, {}, {}};
                }
                if (tableRun && !run.multipleOnly && run.method == RenderMethod::VrlLightcuts) {
                    report.surfaceStats = {stats.surfaceMeanEvaluated, stats.surfaceMeanIntersected};
                    for (const char* counter : {"medium-surface-eval", "medium-surface-inter"})
                        if (const Image* layer = layerOf(images, counter))
                            lastOfMethod[std::string("vrl-lightcuts/") + counter] = ImageSet{*layer, {}, {}, {}};
                }
                if (run.multipleOnly == wholeImage) {  // not the part the previews show
                    results.push_back(std::move(r));
                    continue;
                }
                if (run.method != RenderMethod::VrlLightcuts || run.errorThreshold == 0.02f) {
                    lastOfMethod[std::string(methodName(run.method))] = ImageSet{images.image, {}, {}, {}};
                    lastLabel[std::string(methodName(run.method))] = run.label();
                }
                results.push_back(std::move(r));
            }
            for (const RenderMethod method : {RenderMethod::Path, RenderMethod::Vrl, RenderMethod::VrlLightcuts,
                                              RenderMethod::VrlStochastic, RenderMethod::VplLightcuts}) {
                const std::string m(methodName(method));
                if (!lastOfMethod.count(m)) continue;
                const std::string file = safeName(s.name) + "-" + m + ".png";
                writePreviewPng(lastOfMethod[m].image, o.out / "images" / file, exposure);
                row += " " + std::string(methodTitle(method)) + ", " + lastLabel[m] + " |";
                header += "---|";
                imageRow += " ![](images/" + file + ") |";
            }
            report.images.push_back(row);
            report.images.push_back(header + "---|");
            report.images.push_back(imageRow + "\n");
            // Figure 6: #Eval and #Inter in false colour, one scale per counter for both methods.
            for (const char* counter : {"eval", "inter"}) {
                float clip = 0.0f;
                for (const RenderMethod method : {RenderMethod::VplLightcuts, RenderMethod::VrlLightcuts}) {
                    const auto it = lastOfMethod.find(std::string(methodName(method)) + "/" + counter);
                    if (it != lastOfMethod.end()) clip = std::max(clip, percentileValue(it->second.image, 0.98f));
                }
                std::string line = "| #" + std::string(counter == std::string("eval") ? "Eval" : "Inter") +
                                   " (scale 0 to " + fmt(clip, 4) + ", 98th percentile) |";
                for (const RenderMethod method : {RenderMethod::VplLightcuts, RenderMethod::VrlLightcuts}) {
                    const std::string m(methodName(method));
                    const auto it = lastOfMethod.find(m + "/" + counter);
                    if (it == lastOfMethod.end()) continue;
                    const std::string file = safeName(s.name) + "-" + m + "-" + counter + ".png";
                    writeFalseColourPng(it->second.image, clip, o.out / "images" / file);
                    line += " ![" + std::string(methodTitle(method)) + "](images/" + file + ") |";
                }
                if (counter == std::string("eval")) {
                    report.images.push_back("Figure 6 (N = " + std::to_string(s.tableLights) +
                                            ", part (d)'s cuts): left VPL Lightcuts, right VRL Lightcuts.\n");
                    report.images.push_back("| counter | VPL Lightcuts | VRL Lightcuts |");
                    report.images.push_back("|---|---|---|");
                }
                report.images.push_back(line);
            }
            // Part (c)'s cuts (VRL Lightcuts only), each counter on its own scale.
            for (const char* counter : {"medium-surface-eval", "medium-surface-inter"}) {
                const auto it = lastOfMethod.find(std::string("vrl-lightcuts/") + counter);
                if (it == lastOfMethod.end()) continue;
                const float clip = percentileValue(it->second.image, 0.98f);
                const std::string file = safeName(s.name) + "-vrl-lightcuts-" + counter + ".png";
                writeFalseColourPng(it->second.image, clip, o.out / "images" / file);
                report.images.push_back("| part (c) #" +
                                        std::string(counter == std::string("medium-surface-eval") ? "Eval" : "Inter") +
                                        " (scale 0 to " + fmt(clip, 4) + ") | | ![VRL Lightcuts, part (c)](images/" +
                                        file + ") |");
            }
            const auto measured = measureSpeedup(s, *scene, log);
            speedups.insert(speedups.end(), measured.begin(), measured.end());
        });
        scenes.push_back(std::move(report));
        // Write what we have after every scene: a long report interrupted keeps its data.
        std::ofstream csv(o.out / "results.csv");
        csv << "scene,method,setting,vrls,spp,error_threshold,seconds,rmse,rel_rmse,smape,mean_eval,mean_inter,mean_cut,"
               "mean_ratio,cut_size,ref_noise_rmse,below_noise,part,renders,rmse_min,rmse_max,distance_samples\n";
        csv << std::setprecision(6);
        for (const auto& r : results)
            csv << r.scene << "," << methodName(r.run.method) << "," << r.run.label() << "," << r.run.lights << "," << r.run.spp << ","
                << r.run.errorThreshold << "," << r.seconds << "," << r.metrics.rmse << "," << r.metrics.relativeRmse << ","
                << r.metrics.smape << "," << r.stats.meanEvaluated << "," << r.stats.meanIntersected << ","
                << r.stats.meanCutSize << ","
                << (r.metrics.meanReference > 0 ? r.metrics.meanTest / r.metrics.meanReference : 0.0) << ","
                << r.run.cutSize << "," << r.referenceNoiseRmse << "," << (r.belowNoise() ? 1 : 0) << ","
                << (r.run.multipleOnly ? "multiple" : "image") << "," << r.renders << "," << r.rmseMin << ","
                << r.rmseMax << "," << distanceSamplesColumn(r.run)
                << "\n";
        std::ofstream sp(o.out / "speedup.csv");
        sp << "scene,kind,n,brute_seconds_per_pixel,lightcuts_seconds_per_pixel,speedup,mean_eval,mean_inter,"
              "rel_rmse\n";
        sp << std::setprecision(6);
        for (const auto& r : speedups)
            sp << r.scene << "," << r.kind << "," << r.lights << "," << r.bruteSecondsPerPixel << ","
               << r.lightcutsSecondsPerPixel << "," << r.bruteSecondsPerPixel / r.lightcutsSecondsPerPixel << ","
               << r.meanEval << "," << r.meanInter << "," << r.error << "\n";
    }
    if (o.buildReferences) {
        log.line("references done in %.1f min (in %s)", secondsSince(start) / 60.0,
                 (o.quick ? o.out / "cache" : o.references).string().c_str());
        return 0;
    }
    if (results.empty()) throw std::runtime_error("no benchmark scene could be rendered");
    if (o.plots) {
        const std::string command = o.python + " " + (fs::path(VRL_SOURCE_DIR) / "bench" / "plot_report.py").string() +
                                    " --results " + (o.out / "results.csv").string() + " --speedup " +
                                    (o.out / "speedup.csv").string() + " --out " + o.out.string();
        log.line("plots: %s", command.c_str());
        if (std::system(command.c_str()) != 0)
            throw std::runtime_error("the plot script failed (is python3-matplotlib installed? --no-plots skips it)");
    }
    writeSummary(o.out / "summary.md", o, scenes, results, speedups, secondsSince(start), threads);
    log.line("report done in %.1f min: %s", secondsSince(start) / 60.0, (o.out / "summary.md").string().c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"vrl_report: error against run time for path tracing, plain VRLs, VRL Lightcuts, stochastic VRL "
                 "Lightcuts and VPL Lightcuts on the benchmark scenes, for the whole image and part (d) alone (CSV, "
                 "plots, false-colour statistics, Markdown summary)"};
    Options o;
    app.add_option("-o,--out", o.out, "Output folder (created; default report)");
    app.add_flag("--quick", o.quick, "A small version (our own scene at 32x24, and its g = 0.7 variant on part "
                                     "(d) alone; short sweeps): under 3 minutes; its references go to OUT/cache");
    app.add_flag("--references", o.buildReferences,
                 "Only build the references that are missing (the whole image by the path tracer, or by light "
                 "tracing to the camera where a scene says so; part (d) by plain VRLs over independent VRL sets; "
                 "hours) and the missing check of bathroom's part (d) reference (about 2.5 min, stored beside it, "
                 "outside --reference-minutes), then stop");
    app.add_option("--reference-minutes", o.referenceMinutes,
                   "--references: stop each scene's references after about this many minutes, at least one chunk "
                   "each (0, the default: no limit); the chunks done are kept and a later run resumes them")
        ->check(CLI::NonNegativeNumber);
    app.add_option("--part-reference-chunks", o.partReferenceChunks,
                   "Part (d) references of this many chunks per half (a chunk: the scene's VRL sets per chunk, 5 "
                   "for most, in each half; default: the scene's, 8). More than 8: --references extends the stored "
                   "8-chunk reference (resumable, like every reference); a report run uses the longer one once it "
                   "is stored, and the 8-chunk one until then, saying so")
        ->check(CLI::Range(kReferenceChunks, 1000));
    app.add_option("--references-dir", o.references,
                   "Where references are kept and looked up by a hash of scene, settings and method (default "
                   "bench/references in the source tree)");
    app.add_option("--scenes", o.only, "Only these scenes (names as in the summary), comma-separated")->delimiter(',');
    app.add_option("--shared", o.shared, "The shared scene folder with staircase/, veach-lamp-mitsuba-bidir/, "
                                         "volumetric-caustic/ (default ../shared/scenes beside the repository)");
    app.add_option("--threads", o.threads, "Threads; 0 (the default) = all cores")->check(CLI::Range(0, 4096));
    app.add_option("--python", o.python, "Python with matplotlib for the plots (default /usr/bin/python3)");
    bool noPlots = false;
    app.add_flag("--no-plots", noPlots, "Skip the plots (CSV, images and summary only)");
    CLI11_PARSE(app, argc, argv);
    o.plots = !noPlots;
    spdlog::set_level(spdlog::level::err);  // per-render warnings would repeat for every run
    try {
        return runReport(o);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vrl_report: error: %s\n", e.what());
        return 1;
    }
}
