// The VRL image against the reference path tracer: the four transport parts
// (a)+(b)+(c)+(d) add up to the path-traced image, and part (d) alone equals the
// path tracer restricted to paths whose first two camera vertices are in a
// medium. Both estimators are run K times with independent seeds (the VRLs of
// one run are shared by all its pixels, so pixels are not independent); the
// image mean and each 8x8 block mean must agree within 5 combined standard
// errors of the K-run means (Student t with K-1 = 7 dof: P(|t| > 5) = 0.0016
// per comparison, about 2% over the 15 comparisons of one scene). The sanitizer
// build runs them on a quarter of the samples and lights (test_workload.h).
#include "render/integrators/path_tracer.h"
#include "render/integrators/transport_integrator.h"
#include "render/renderer.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "tests/support/test_scenes.h"
#include "tests/support/test_workload.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <filesystem>
#include <vector>

namespace vrl {
namespace {

constexpr int kRuns = 8;
constexpr int kBlock = 8;
constexpr int kReferenceSpp = 2048 / test::kSanitizedWorkDivisor;  // per pixel and run
constexpr uint64_t kVrls = 6000 / test::kSanitizedWorkDivisor;      // per run
// Samples per pixel of the path-sampled parts (a)-(c) in the four-part runs.
constexpr int kPartsSpp = 16 / test::kSanitizedWorkDivisor;
// The four parts (a)+(b)+(c)+(d), the whole image.
constexpr const char* kAllParts = "surface,single,medium-surface,multiple";

// Block means (plus the whole-image mean last) of one image, per channel.
std::vector<Rgb> blockMeans(const Image& image) {
    std::vector<Rgb> means;
    for (int by = 0; by < image.height(); by += kBlock) {
        for (int bx = 0; bx < image.width(); bx += kBlock) {
            Rgb sum(0.0f);
            for (int y = by; y < by + kBlock; ++y)
                for (int x = bx; x < bx + kBlock; ++x) sum += image.at(x, y);
            means.push_back(sum / float(kBlock * kBlock));
        }
    }
    Rgb all(0.0f);
    for (const auto& p : image.pixels()) all += p;
    means.push_back(all / float(image.pixelCount()));
    return means;
}

struct RunStatistics {
    std::vector<Rgb> mean, standardError;
};

template <class RenderRun>
RunStatistics overRuns(RenderRun&& renderRun) {
    std::vector<std::vector<Rgb>> runs;
    for (int r = 0; r < kRuns; ++r) runs.push_back(blockMeans(renderRun(uint64_t(r + 1))));
    RunStatistics s;
    const size_t n = runs[0].size();
    s.mean.assign(n, Rgb(0.0f));
    s.standardError.assign(n, Rgb(0.0f));
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            double sum = 0, sum2 = 0;
            for (const auto& run : runs) {
                sum += run[i][c];
                sum2 += double(run[i][c]) * run[i][c];
            }
            const double mean = sum / kRuns;
            s.mean[i][c] = float(mean);
            s.standardError[i][c] = float(std::sqrt(std::max(0.0, sum2 / kRuns - mean * mean) / (kRuns - 1)));
        }
    }
    return s;
}

void expectAgree(const RunStatistics& vrl, const RunStatistics& reference, const char* what) {
    for (size_t i = 0; i < vrl.mean.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
            const double se = std::hypot(vrl.standardError[i][c], reference.standardError[i][c]);
            const char* region = i + 1 == vrl.mean.size() ? "image" : "block";
            EXPECT_NEAR(vrl.mean[i][c], reference.mean[i][c], 5.0 * se + 1e-7)
                << what << ": " << region << " " << i << " channel " << c;
        }
    }
    // The comparison must have power: the image mean is resolved to a few percent.
    const size_t image = vrl.mean.size() - 1;
    std::printf("%s: image mean (green) vrl %.5f +- %.5f, reference %.5f +- %.5f\n", what, vrl.mean[image][1], vrl.standardError[image][1], reference.mean[image][1], reference.standardError[image][1]);
    EXPECT_GT(reference.mean[image][1], 0.0f);
    EXPECT_LT(vrl.standardError[image][1], 0.05f * test::kSanitizedNoiseFactor * reference.mean[image][1]) << what << ": too noisy to mean much";
}

// `jittered`: each sample's ray through a uniform point of its pixel (the pixel's mean), else its centre.
RunStatistics referenceRuns(const Scene& scene, int spp, bool onlyMediumToMedium, int maxDepth = -1,
                            const PathStart& start = {}, bool jittered = false) {
    return overRuns([&](uint64_t seed) {
        Image image(scene.camera().width(), scene.camera().height());
        const VolumetricPathTracer tracer(scene, PathTracerSettings{maxDepth, 5, onlyMediumToMedium});
        tbb::parallel_for(0, image.height(), [&](int y) {
            for (int x = 0; x < image.width(); ++x) {
                Rng rng(seed * 7919, uint64_t(y * image.width() + x));
                const Ray centre = scene.camera().generateRay(x + 0.5f, y + 0.5f);
                Rgb sum(0.0f);
                for (int s = 0; s < spp; ++s) {
                    const Ray ray = jittered ? scene.camera().generateRay(x + rng.next(), y + rng.next()) : centre;
                    sum += tracer.radiance(ray, scene.cameraMedium(), rng, start);
                }
                image.at(x, y) = sum / float(spp);
            }
        });
        return image;
    });
}

RunStatistics vrlRuns(const Scene& scene, const std::string& transports, int spp, uint64_t vrls, int maxDepth = -1,
                      RenderMethod method = RenderMethod::Vrl, bool jittered = false) {
    return overRuns([&](uint64_t seed) {
        RenderSettings settings;
        settings.method = method;
        settings.transports = TransportSelection::parse(transports);
        settings.samplesPerPixel = spp;
        settings.vrlCount = vrls;
        settings.seed = seed;
        settings.maxDepth = maxDepth;
        settings.jitter = jittered;
        return render(scene, settings).image;
    });
}

// Isotropic grey, chromatic, and HG g = 0.7 media.
struct MediumCase {
    const char* name;
    Rgb sigmaS, sigmaA;
    float g;
};
const MediumCase kMedia[] = {{"grey", Rgb(0.8f), Rgb(0.2f), 0.0f},
                             {"chromatic", Rgb(0.4f, 0.8f, 1.4f), Rgb(0.2f, 0.1f, 0.05f), 0.0f},
                             {"hg0.7", Rgb(0.8f), Rgb(0.2f), 0.7f}};

// Also with stochastic VRL Lightcuts ((c), (d) per camera sample, unbiased).
TEST(VrlImage, PartsSumToReferenceInMediumOnlyScene) {
    for (const MediumCase& m : kMedia) {
        const auto scene = Scene::build(test::mediumOnlyCube(m.sigmaS, m.sigmaA, m.g));
        const RunStatistics reference = referenceRuns(*scene, kReferenceSpp, false);
        expectAgree(vrlRuns(*scene, kAllParts, kPartsSpp, kVrls), reference, m.name);
        expectAgree(vrlRuns(*scene, kAllParts, kPartsSpp, kVrls, -1, RenderMethod::VrlStochastic),
                    reference, (std::string(m.name) + " vrl-stochastic").c_str());
    }
}

// Camera paths continue through glass and a mirror (camera_segment.h); light
// paths refract into volumetric caustics. Grey medium only, to keep the time down.
// The room's area light only (test::withoutPointLights): its spot light's caustics
// through the glass reach the VRLs but not the path tracer, so with it the reference
// would lack light the VRL image has (light_tracing_reference_test.cpp measures it).
TEST(VrlImage, PartsSumToReferenceThroughGlassAndMirror) {
    const MediumCase& m = kMedia[0];
    const auto scene =
        Scene::build(test::withoutPointLights(test::glassAndMirrorRoom(m.sigmaS * 0.5f, m.sigmaA * 0.5f, m.g)));
    ASSERT_TRUE(scene->hasSpecularSurfaces());
    expectAgree(vrlRuns(*scene, kAllParts, kPartsSpp, kVrls),
                referenceRuns(*scene, kReferenceSpp, false), "glass and mirror");
}

// The lajolla Cornell box (spectral reflectances, a medium around everything) as
// written, at 16x16: the four-part VRL image equals the path tracer within noise.
TEST(VrlImage, PartsSumToReferenceInSharedVolCbox) {
    const std::filesystem::path file = std::filesystem::path(VRL_SHARED_SCENES_DIR) / "lajolla-volpath-test/vol_cbox.xml";
    if (!std::filesystem::exists(file)) GTEST_SKIP() << "shared scene " << file << " is absent";
    SceneDescription description = parseMitsubaScene(file);
    description.sensor.width = description.sensor.height = 16;
    const auto scene = Scene::build(description);
    expectAgree(vrlRuns(*scene, kAllParts, kPartsSpp, kVrls),
                referenceRuns(*scene, kReferenceSpp, false), "vol_cbox");
}

// Part (c) alone, VRL-lit surfaces (plain VRLs and Lightcuts at the default 2%
// threshold), equals the path tracer restricted to paths whose first camera
// vertex is on a surface and whose second is in the medium.
RunStatistics surfaceThenMediumReference(const Scene& scene) {
    return referenceRuns(scene, kReferenceSpp, false, -1,
                         PathStart{0, true, false, false, PathStart::AfterFirstSurface::InMedium});
}

TEST(VrlImage, MediumSurfaceEqualsRestrictedReference) {
    for (const MediumCase& m : kMedia) {
        const auto scene = Scene::build(test::litRoomWithOccluder(m.sigmaS * 0.5f, m.sigmaA * 0.5f, m.g));
        const RunStatistics reference = surfaceThenMediumReference(*scene);
        expectAgree(vrlRuns(*scene, "medium-surface", 1, kVrls), reference, m.name);
        expectAgree(vrlRuns(*scene, "medium-surface", 1, kVrls, -1, RenderMethod::VrlLightcuts), reference,
                    (std::string(m.name) + " lightcuts").c_str());
    }
}

// With jittered rays, (c) is the pixel's mean: its VRLs interleaved over 2 x 2 points
// of each pixel (interleaved_points.h), plain and by a cut chosen at one of them,
// against the path tracer restricted as above with jittered rays. The lit room's
// occluder puts edges inside pixels. Grey medium only, to keep the time down.
TEST(VrlImage, MediumSurfaceJitteredEqualsRestrictedReference) {
    const MediumCase& m = kMedia[0];
    const auto scene = Scene::build(test::litRoomWithOccluder(m.sigmaS * 0.5f, m.sigmaA * 0.5f, m.g));
    const RunStatistics reference = referenceRuns(*scene, kReferenceSpp, false, -1,
                                                  PathStart{0, true, false, false, PathStart::AfterFirstSurface::InMedium},
                                                  true);
    expectAgree(vrlRuns(*scene, "medium-surface", 1, kVrls, -1, RenderMethod::Vrl, true), reference,
                "grey, jittered");
    expectAgree(vrlRuns(*scene, "medium-surface", 1, kVrls, -1, RenderMethod::VrlLightcuts, true), reference,
                "grey, jittered, lightcuts");
}

TEST(VrlImage, MediumSurfaceEqualsRestrictedReferenceInSharedVolCbox) {
    const std::filesystem::path file = std::filesystem::path(VRL_SHARED_SCENES_DIR) / "lajolla-volpath-test/vol_cbox.xml";
    if (!std::filesystem::exists(file)) GTEST_SKIP() << "shared scene " << file << " is absent";
    SceneDescription description = parseMitsubaScene(file);
    description.sensor.width = description.sensor.height = 16;
    const auto scene = Scene::build(description);
    const RunStatistics reference = surfaceThenMediumReference(*scene);
    expectAgree(vrlRuns(*scene, "medium-surface", 1, kVrls), reference, "vol_cbox (c)");
    expectAgree(vrlRuns(*scene, "medium-surface", 1, kVrls, -1, RenderMethod::VrlLightcuts), reference,
                "vol_cbox (c) lightcuts");
    // The whole four-part image with both parts (c) and (d) by Lightcuts.
    expectAgree(vrlRuns(*scene, kAllParts, kPartsSpp, kVrls, -1, RenderMethod::VrlLightcuts),
                referenceRuns(*scene, kReferenceSpp, false), "vol_cbox lightcuts");
}

TEST(VrlImage, PartsSumToReferenceInLitRoomWithOccluder) {
    for (const MediumCase& m : kMedia) {
        const auto scene = Scene::build(test::litRoomWithOccluder(m.sigmaS * 0.5f, m.sigmaA * 0.5f, m.g));
        const RunStatistics reference = referenceRuns(*scene, kReferenceSpp, false);
        expectAgree(vrlRuns(*scene, kAllParts, kPartsSpp, kVrls), reference, m.name);
        expectAgree(vrlRuns(*scene, kAllParts, kPartsSpp, kVrls, -1, RenderMethod::VrlStochastic),
                    reference, (std::string(m.name) + " vrl-stochastic").c_str());
    }
}

// Part (a) alone with vrl-lightcuts, its light from non-Dirac reflections at x2
// sampled from the surface VPLs per camera sample (the inverse square clamped,
// path tracing adding the rest within R), equals part (a) path-traced alone
// (--surface-vpls 0): the split is unbiased. The lit room (grey and HG media),
// the room with a narrow-lobe (alpha 0.1: path-traced) and a broad (alpha 0.4:
// from its VPLs) glossy reflector, and the shared Cornell box.
RunStatistics surfacePartRuns(const Scene& scene, uint64_t surfaceVplLimit) {
    return overRuns([&](uint64_t seed) {
        RenderSettings settings;
        settings.method = RenderMethod::VrlLightcuts;
        settings.transports = TransportSelection::parse("surface");
        settings.samplesPerPixel = kPartsSpp;
        settings.vrlCount = kVrls;
        settings.surfaceVplLimit = surfaceVplLimit;
        settings.seed = seed;
        return render(scene, settings).image;
    });
}

TEST(VrlImage, SurfacePartWithSurfaceVplsEqualsPathTracedSurfacePart) {
    std::vector<std::pair<std::string, std::unique_ptr<Scene>>> scenes;
    for (const MediumCase& m : {kMedia[0], kMedia[2]})
        scenes.emplace_back(m.name, Scene::build(test::litRoomWithOccluder(m.sigmaS * 0.5f, m.sigmaA * 0.5f, m.g)));
    // A narrow-lobe reflector whose light stays path-traced and a broad one whose VPLs take part.
    scenes.emplace_back(std::string(kMedia[0].name) + ", glossy reflectors",
                        Scene::build(test::roomWithGlossyReflectors(kMedia[0].sigmaS * 0.5f, kMedia[0].sigmaA * 0.5f,
                                                                    kMedia[0].g)));
    const std::filesystem::path file = std::filesystem::path(VRL_SHARED_SCENES_DIR) / "lajolla-volpath-test/vol_cbox.xml";
    if (std::filesystem::exists(file)) {
        SceneDescription description = parseMitsubaScene(file);
        description.sensor.width = description.sensor.height = 16;
        scenes.emplace_back("vol_cbox", Scene::build(description));
    } else {
        std::printf("shared scene %s is absent: the lit room only\n", file.c_str());
    }
    for (const auto& [name, scene] : scenes) {
        expectAgree(surfacePartRuns(*scene, kAutoSurfaceVpls), surfacePartRuns(*scene, 0),
                    (name + " (a) with surface VPLs").c_str());
    }
}

TEST(VrlImage, MultipleScatteringEqualsRestrictedReference) {
    for (const MediumCase& m : kMedia) {
        const auto scene = Scene::build(test::litRoomWithOccluder(m.sigmaS * 0.5f, m.sigmaA * 0.5f, m.g));
        expectAgree(vrlRuns(*scene, "multiple", 1, kVrls), referenceRuns(*scene, kReferenceSpp, true), m.name);
    }
}

// maxDepth bookkeeping of every part: 3 allows double scattering and one bounce
// after a medium vertex; 4 one more.
TEST(VrlImage, PartsSumToReferenceWithDepthLimit) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    for (int depth : {2, 3, 4}) {
        const std::string what = "maxDepth " + std::to_string(depth);
        expectAgree(vrlRuns(*scene, kAllParts, kPartsSpp, kVrls, depth),
                    referenceRuns(*scene, kReferenceSpp / 2, false, depth), what.c_str());
    }
}

TEST(VrlImage, LayersAreThePartsAndSumToTheImage) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    RenderSettings settings;
    settings.method = RenderMethod::Vrl;
    settings.samplesPerPixel = 2;
    settings.vrlCount = 500;
    const ImageSet out = render(*scene, settings);
    // The four parts, then part (b)'s light from surface VPLs (once per pixel).
    ASSERT_EQ(out.layers.size(), 5u);
    const char* names[] = {"surface", "single", "medium-surface", "multiple", "single-vpl"};
    for (size_t i = 0; i < 5; ++i) EXPECT_EQ(out.layers[i].first, names[i]);
    for (size_t p = 0; p < out.image.pixelCount(); ++p) {
        Rgb sum(0.0f);
        for (const auto& layer : out.layers) sum += layer.second[p];
        ASSERT_NEAR(out.image[p].x, sum.x, 1e-6f * (1.0f + sum.x));
        for (const auto& layer : out.layers) {
            ASSERT_TRUE(isFinite(layer.second[p]));
            ASSERT_GE(minComponent(layer.second[p]), 0.0f);
        }
    }
    settings.transports = TransportSelection::parse("single,multiple");
    EXPECT_EQ(render(*scene, settings).layers.size(), 3u);
    settings.transports = TransportSelection::parse("surface,multiple");  // no (b): no surface VPL layer
    EXPECT_EQ(render(*scene, settings).layers.size(), 2u);
    EXPECT_THROW(TransportSelection::parse("single,bogus"), std::invalid_argument);
}

}  // namespace
}  // namespace vrl
