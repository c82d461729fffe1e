// Tests for the one builder of RenderSettings from a job spec
// (service/job/job_scene.cpp: resolveJob): the method a spec leaves empty comes
// from the scene's <integrator> when that names one of ours, else the headline
// method; the crop window applies after the resolution and is checked against
// the resolved film; a -D the scene does not use fails the job before rendering.
#include "service/job/job_scene.h"

#include "tests/support/temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>

namespace vrl {
namespace {

// A tiny scene with `integrator` (e.g. "<integrator type=\"vrl\"/>") and a 32x24 film.
std::filesystem::path writeScene(const test::TempDir& dir, const std::string& integrator,
                                 const std::string& filmExtra = "") {
    const std::filesystem::path file = dir / "scene.xml";
    std::ofstream(file) << "<scene version=\"0.5.0\">\n  <default name=\"spp\" value=\"2\"/>\n  " << integrator
                        << "\n  <sensor type=\"perspective\"><sampler type=\"independent\"><integer name=\"sampleCount\" "
                           "value=\"$spp\"/></sampler>\n    <film type=\"hdrfilm\"><integer name=\"width\" value=\"32\"/>"
                           "<integer name=\"height\" value=\"24\"/>"
                        << filmExtra << "</film></sensor>\n</scene>\n";
    return file;
}

v1::JobSpec specWithMethod(const std::string& method) {
    v1::JobSpec spec;
    *spec.mutable_parameters() = rpc::defaultRenderParameters(RenderMethod::Path);
    spec.mutable_parameters()->set_method(method);
    return spec;
}

TEST(ResolveJob, EmptyMethodTakesTheScenesIntegratorWhenItNamesOurs) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "<integrator type=\"vrl\"><integer name=\"maxDepth\" value=\"4\"/></integrator>");
    const rpc::ResolvedJob job = rpc::resolveJob(scene, specWithMethod(""), {});
    EXPECT_EQ(job.settings.method, RenderMethod::Vrl);
    EXPECT_EQ(job.settings.maxDepth, 4);  // the scene's integrator keeps its depth
    for (const RenderMethod method : kRenderMethods) {
        const auto named = writeScene(dir, "<integrator type=\"" + std::string(methodName(method)) + "\"/>");
        EXPECT_EQ(rpc::resolveJob(named, specWithMethod(""), {}).settings.method, method) << methodName(method);
    }
}

TEST(ResolveJob, EmptyMethodWithAnotherIntegratorIsTheHeadlineMethod) {
    static_assert(kHeadlineMethod == RenderMethod::VrlLightcuts);
    const test::TempDir dir("vrl-job-scene");
    for (const std::string integrator : {"<integrator type=\"volpath\"/>", "<integrator type=\"vrlcuts\"/>",
                                         "<integrator type=\"bdpt\"/>", ""})
        EXPECT_EQ(rpc::resolveJob(writeScene(dir, integrator), specWithMethod(""), {}).settings.method,
                  kHeadlineMethod)
            << integrator;
}

TEST(ResolveJob, AnExplicitMethodWinsOverTheScenes) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "<integrator type=\"vrl\"/>");
    EXPECT_EQ(rpc::resolveJob(scene, specWithMethod("path"), {}).settings.method, RenderMethod::Path);
    EXPECT_EQ(rpc::resolveJob(scene, specWithMethod("vpl-lightcuts"), {}).settings.method, RenderMethod::VplLightcuts);
}

TEST(ResolveJob, AMethodFromTheSceneStillNeedsLights) {
    const test::TempDir dir("vrl-job-scene");
    v1::JobSpec spec = specWithMethod("");
    spec.mutable_parameters()->set_vrl_count(0);
    try {
        rpc::resolveJob(writeScene(dir, "<integrator type=\"vrl\"/>"), spec, {});
        ADD_FAILURE() << "no VRLs accepted";
    } catch (const rpc::JobSpecError& e) {
        EXPECT_NE(std::string(e.what()).find("method vrl needs a VRL count"), std::string::npos) << e.what();
    }
    spec.mutable_parameters()->set_method("path");
    EXPECT_NO_THROW(rpc::resolveJob(writeScene(dir, "<integrator type=\"vrl\"/>"), spec, {}));
}

// A time limit makes the sample count a cap: the spec's, or no cap (the most a
// job may have) where the spec leaves it to the scene; a negative, NaN or
// absurd limit is refused before the scene is read.
TEST(ResolveJob, ATimeLimitMakesTheSampleCountACap) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "");  // sampleCount 2
    v1::JobSpec spec = specWithMethod("path");
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.samplesPerPixel, 2);
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.timeLimitSeconds, 0.0);
    spec.mutable_parameters()->set_time_limit_seconds(30.0);
    rpc::ServiceLimits limits;
    limits.maxSamplesPerPixel = 4096;
    const RenderSettings capped = rpc::resolveJob(scene, spec, limits).settings;
    EXPECT_EQ(capped.timeLimitSeconds, 30.0);
    EXPECT_EQ(capped.samplesPerPixel, 4096);
    spec.mutable_parameters()->set_samples_per_pixel(100);
    EXPECT_EQ(rpc::resolveJob(scene, spec, limits).settings.samplesPerPixel, 100);
    for (const double bad : {-1.0, std::nan(""), 1e30, -std::numeric_limits<double>::infinity()}) {
        spec.mutable_parameters()->set_time_limit_seconds(bad);
        try {
            rpc::validateJobSpec(spec, {});
            ADD_FAILURE() << "time limit " << bad << " accepted";
        } catch (const rpc::JobSpecError& e) {
            EXPECT_NE(std::string(e.what()).find("time limit"), std::string::npos) << e.what();
        }
    }
}

// The HG bound of VRL cuts: the proven cone bound unless the spec asks for the
// (1 + hg_epsilon) heuristic; the defaults the client starts from say "cones".
TEST(ResolveJob, HgBoundIsTheProvenOneUnlessTheHeuristicIsAskedFor) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "");
    v1::JobSpec spec = specWithMethod("vrl-lightcuts");
    EXPECT_FALSE(rpc::defaultRenderParameters(RenderMethod::VrlLightcuts).hg_epsilon_bound());
    RenderSettings s = rpc::resolveJob(scene, spec, {}).settings;
    EXPECT_EQ(s.cut.bound.hgBound, HgBound::Cones);
    spec.mutable_parameters()->set_hg_epsilon_bound(true);
    spec.mutable_parameters()->set_hg_epsilon(0.5f);
    s = rpc::resolveJob(scene, spec, {}).settings;
    EXPECT_EQ(s.cut.bound.hgBound, HgBound::Epsilon);
    EXPECT_EQ(s.cut.bound.anisotropyEpsilon, 0.5f);
}

// Part (c)'s bound at glossy surfaces: the proven cone bound unless the spec asks for
// the heuristic; the defaults the client starts from say "cones".
TEST(ResolveJob, GlossyBoundIsTheProvenOneUnlessTheHeuristicIsAskedFor) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "");
    v1::JobSpec spec = specWithMethod("vrl-lightcuts");
    EXPECT_FALSE(rpc::defaultRenderParameters(RenderMethod::VrlLightcuts).glossy_heuristic_bound());
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.cut.bound.glossyBound, GlossyBound::Cones);
    spec.mutable_parameters()->set_glossy_heuristic_bound(true);
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.cut.bound.glossyBound, GlossyBound::Corners);
}

TEST(ResolveJob, VrlSetsAreForVrlStochasticWithinTheVrlLimit) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "");
    v1::JobSpec spec = specWithMethod("vrl-stochastic");
    spec.mutable_parameters()->set_vrl_count(1000);
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.vrlSets, 1);  // 0: one set
    spec.mutable_parameters()->set_vrl_sets(5);
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.vrlSets, 5);
    const auto rejects = [&](const v1::JobSpec& bad, const rpc::ServiceLimits& limits, const std::string& words) {
        try {
            rpc::resolveJob(scene, bad, limits);
            ADD_FAILURE() << "accepted: " << bad.ShortDebugString();
        } catch (const rpc::JobSpecError& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    v1::JobSpec tooMany = spec;
    tooMany.mutable_parameters()->set_vrl_sets(uint32_t(kMaxVrlSets) + 1);
    rejects(tooMany, {}, "VRL sets must be in 1..." + std::to_string(kMaxVrlSets));
    rpc::ServiceLimits limits;
    limits.maxVrls = 4000;  // 5 sets of 1000 VRLs are over it, one set is not
    rejects(spec, limits, "5 VRL sets of 1000");
    v1::JobSpec lightcuts = spec;
    lightcuts.mutable_parameters()->set_method("vrl-lightcuts");
    rejects(lightcuts, {}, "need the vrl-stochastic method");
}

// The VPL methods' distance samples travel in the spec (0: the default, 32) and
// are checked against kMaxVplDistanceSamples before any work.
TEST(ResolveJob, VplDistanceSamplesComeFromTheSpec) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "");
    v1::JobSpec spec = specWithMethod("vpl-lightcuts");
    EXPECT_EQ(rpc::defaultRenderParameters(RenderMethod::VplLightcuts).vpl_distance_samples(),
              uint32_t(RenderSettings{}.vplDistanceSamples));
    spec.mutable_parameters()->set_vpl_distance_samples(0);
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.vplDistanceSamples, RenderSettings{}.vplDistanceSamples);
    spec.mutable_parameters()->set_vpl_distance_samples(4);
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.vplDistanceSamples, 4);
    spec.mutable_parameters()->set_vpl_distance_samples(uint32_t(kMaxVplDistanceSamples));
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.vplDistanceSamples, kMaxVplDistanceSamples);
    spec.mutable_parameters()->set_vpl_distance_samples(uint32_t(kMaxVplDistanceSamples) + 1);
    try {
        rpc::validateJobSpec(spec, {});
        ADD_FAILURE() << "distance samples " << kMaxVplDistanceSamples + 1 << " accepted";
    } catch (const rpc::JobSpecError& e) {
        EXPECT_NE(std::string(e.what()).find("VPL distance samples per camera segment must be in 1..." +
                                             std::to_string(kMaxVplDistanceSamples)),
                  std::string::npos)
            << e.what();
    }
}

// The surface VPL limit travels in the spec: 0 the default, -1 none (the render
// then path-samples part (b)'s surface light), N a limit up to the coordinator's
// light limit; anything else is refused before any work.
TEST(ResolveJob, SurfaceVplLimitComesFromTheSpec) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "");
    v1::JobSpec spec = specWithMethod("vrl-lightcuts");
    EXPECT_EQ(rpc::defaultRenderParameters(RenderMethod::VrlLightcuts).surface_vpls(), 0);
    RenderSettings settings = rpc::resolveJob(scene, spec, {}).settings;
    EXPECT_EQ(settings.surfaceVplLimit, kAutoSurfaceVpls);
    EXPECT_EQ(surfaceVplLimit(settings), settings.vrlCount);
    EXPECT_TRUE(usesSurfaceVpls(settings));
    spec.mutable_parameters()->set_surface_vpls(-1);
    settings = rpc::resolveJob(scene, spec, {}).settings;
    EXPECT_EQ(settings.surfaceVplLimit, 0u);
    EXPECT_FALSE(usesSurfaceVpls(settings));
    spec.mutable_parameters()->set_surface_vpls(5000);
    settings = rpc::resolveJob(scene, spec, {}).settings;
    EXPECT_EQ(surfaceVplLimit(settings), 5000u);
    EXPECT_TRUE(usesSurfaceVpls(settings));
    spec.mutable_parameters()->set_vrl_count(1000);
    rpc::ServiceLimits limits;
    limits.maxVrls = 4000;
    for (const auto& [value, limit] : {std::pair<int64_t, rpc::ServiceLimits>{-2, {}}, {5000, limits}}) {
        spec.mutable_parameters()->set_surface_vpls(value);
        try {
            rpc::validateJobSpec(spec, limit);
            ADD_FAILURE() << "surface VPLs " << value << " accepted";
        } catch (const rpc::JobSpecError& e) {
            EXPECT_NE(std::string(e.what()).find("surface VPLs must be -1 (none), 0 (the default) or 1..."),
                      std::string::npos)
                << e.what();
        }
    }
}

// The shading points per pixel side travel in the spec (0: one) and are checked
// against kMaxShadingPointsPerSide before any work.
TEST(ResolveJob, ShadingPointsComeFromTheSpec) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "");
    v1::JobSpec spec = specWithMethod("vrl-lightcuts");
    EXPECT_EQ(rpc::defaultRenderParameters(RenderMethod::VrlLightcuts).shading_points(), 1u);
    spec.mutable_parameters()->set_shading_points(0);
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.shadingPointsPerSide, 1);
    spec.mutable_parameters()->set_shading_points(3);
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).settings.shadingPointsPerSide, 3);
    spec.mutable_parameters()->set_shading_points(uint32_t(kMaxShadingPointsPerSide) + 1);
    try {
        rpc::validateJobSpec(spec, {});
        ADD_FAILURE() << "shading points " << kMaxShadingPointsPerSide + 1 << " accepted";
    } catch (const rpc::JobSpecError& e) {
        EXPECT_NE(std::string(e.what()).find("shading points per pixel side must be in 1..."), std::string::npos)
            << e.what();
    }
}

TEST(ResolveJob, CropAppliesAfterTheResolution) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "");
    v1::JobSpec spec = specWithMethod("path");
    auto& p = *spec.mutable_parameters();
    p.set_width(64);
    p.set_height(48);
    auto& crop = *p.mutable_crop();
    crop.set_x(40);
    crop.set_y(30);
    crop.set_width(24);
    crop.set_height(18);
    const rpc::ResolvedJob job = rpc::resolveJob(scene, spec, {});
    EXPECT_EQ(job.description.sensor.width, 64);
    EXPECT_EQ(job.description.sensor.crop, (FilmCrop{40, 30, 24, 18}));
    // The same window on the scene's own 32x24 film does not fit: the message names both.
    p.clear_width();
    p.clear_height();
    try {
        rpc::resolveJob(scene, spec, {});
        ADD_FAILURE() << "a crop outside the film was accepted";
    } catch (const rpc::JobSpecError& e) {
        EXPECT_NE(std::string(e.what()).find("crop window 40,30,24,18"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("32x24 film"), std::string::npos) << e.what();
    }
    crop.set_width(0);
    EXPECT_THROW(rpc::resolveJob(scene, spec, {}), rpc::JobSpecError);
    // The whole film is no crop.
    crop.set_x(0);
    crop.set_y(0);
    crop.set_width(32);
    crop.set_height(24);
    EXPECT_FALSE(rpc::resolveJob(scene, spec, {}).description.sensor.crop);
}

TEST(ResolveJob, TheScenesCropMustFitAResolutionAskedFor) {
    const test::TempDir dir("vrl-job-scene");
    const auto scene = writeScene(dir, "", "<integer name=\"cropOffsetX\" value=\"16\"/><integer name=\"cropWidth\" "
                                           "value=\"16\"/>");
    v1::JobSpec spec = specWithMethod("path");
    EXPECT_EQ(rpc::resolveJob(scene, spec, {}).description.sensor.crop, (FilmCrop{16, 0, 16, 24}));
    spec.mutable_parameters()->set_width(20);
    spec.mutable_parameters()->set_height(24);
    try {
        rpc::resolveJob(scene, spec, {});
        ADD_FAILURE() << "the scene's crop outside a smaller film was accepted";
    } catch (const rpc::JobSpecError& e) {
        EXPECT_NE(std::string(e.what()).find("scene's film crop"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("20x24 film"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("--crop"), std::string::npos) << e.what();
    }
}

TEST(ResolveJob, AnUnusedDefineFailsTheJob) {
    const test::TempDir dir("vrl-job-scene");
    v1::JobSpec spec = specWithMethod("path");
    (*spec.mutable_defines())["spp"] = "1";
    EXPECT_NO_THROW(rpc::resolveJob(writeScene(dir, ""), spec, {}));
    (*spec.mutable_defines())["sppp"] = "1";
    try {
        rpc::resolveJob(writeScene(dir, ""), spec, {});
        ADD_FAILURE() << "an unused define was accepted";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("-D sppp=1: the scene uses no $sppp"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("names it uses: spp"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace vrl
