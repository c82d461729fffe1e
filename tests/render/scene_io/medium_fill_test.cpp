// --medium: the fill-medium spec parser and filling a surface-only scene.
#include "render/scene/scene.h"
#include "render/scene_io/medium_fill.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace vrl {
namespace {

TEST(MediumFill, ParsesScalarAndRgbCoefficientsAndHg) {
    const MediumDescription grey = parseFillMedium("sigmaS=0.1,sigmaA=0.02");
    EXPECT_EQ(grey.sigmaS, Rgb(0.1f));
    EXPECT_EQ(grey.sigmaA, Rgb(0.02f));
    EXPECT_EQ(grey.phase.kind, PhaseDescription::Kind::Isotropic);
    const MediumDescription tinted = parseFillMedium("sigmaA=0:0.01:0.02,sigmaS=0.3:0.2:0.1,g=0.4");
    EXPECT_EQ(tinted.sigmaS, Rgb(0.3f, 0.2f, 0.1f));
    EXPECT_EQ(tinted.sigmaA, Rgb(0.0f, 0.01f, 0.02f));
    EXPECT_EQ(tinted.phase.kind, PhaseDescription::Kind::HenyeyGreenstein);
    EXPECT_FLOAT_EQ(tinted.phase.g, 0.4f);
}

TEST(MediumFill, BadSpecsNameTheProblem) {
    const auto message = [](const char* spec) {
        try {
            parseFillMedium(spec);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message("sigmaS=0.1").find("both sigmaS and sigmaA"), std::string::npos);
    EXPECT_NE(message("sigmaS=-1,sigmaA=0").find("non-negative"), std::string::npos);
    EXPECT_NE(message("sigmaS=nan,sigmaA=0").find("not a finite number"), std::string::npos);
    EXPECT_NE(message("sigmaS=1,sigmaA=0,g=1").find("(-1, 1)"), std::string::npos);
    EXPECT_NE(message("sigmaS=1,sigmaA=0,density=3").find("unknown entry 'density'"), std::string::npos);
    EXPECT_NE(message("sigmaS=1:2,sigmaA=0").find("r:g:b"), std::string::npos);
    EXPECT_NE(message("sigmaS").find("name=value"), std::string::npos);
}

TEST(MediumFill, CameraAndLightsSitInTheFill) {
    SceneDescription scene = test::litRoomWithOccluder(Rgb(0.5f), Rgb(0.1f), 0.0f);
    EXPECT_THROW(fillWithMedium(scene, parseFillMedium("sigmaS=0.1,sigmaA=0.02")), SceneError);  // has media
    scene.media.clear();
    scene.sensor.medium = -1;
    fillWithMedium(scene, parseFillMedium("sigmaS=0.1,sigmaA=0.02"));
    ASSERT_EQ(scene.media.size(), 1u);
    EXPECT_EQ(scene.sensor.medium, 0);
    for (const auto& e : scene.emitters) EXPECT_EQ(e.medium, 0);
    const auto built = Scene::build(scene);
    for (const auto& e : built->emitters()) EXPECT_EQ(e->medium, 0);  // the area light is located in it too
    EXPECT_TRUE(scene.approximations.empty());  // no glass here
}

}  // namespace
}  // namespace vrl
