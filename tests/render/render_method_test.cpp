// The method table (render/render_method.h) at run time: every name parses back to
// its method, an unknown name is refused with the valid ones, the "which methods read
// this setting" phrases the command line's warnings print, the predicates the
// renderer and the service branch on, and the counter layers each cut writes. (The
// table's internal consistency is a static_assert there.)
#include "render/render_method.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace vrl {
namespace {

TEST(RenderMethodTable, NamesParseBackInTableOrder) {
    const std::vector<std::string> names = renderMethodNames();
    ASSERT_EQ(names.size(), kRenderMethods.size());
    EXPECT_EQ(names, (std::vector<std::string>{"path", "vrl", "vrl-lightcuts", "vrl-stochastic", "vpl", "vpl-lightcuts"}));
    for (size_t i = 0; i < names.size(); ++i) {
        EXPECT_EQ(parseRenderMethod(names[i]), kRenderMethods[i]) << names[i];
        EXPECT_EQ(methodTraits(kRenderMethods[i]).method, kRenderMethods[i]);
    }
    EXPECT_EQ(methodName(kHeadlineMethod), "vrl-lightcuts");
}

TEST(RenderMethodTable, UnknownNamesAreRefusedWithTheValidOnes) {
    for (const char* bad : {"", "VRL", "vrl_lightcuts", "lightcuts", "path "}) {
        try {
            (void)parseRenderMethod(bad);
            ADD_FAILURE() << "'" << bad << "' was accepted";
        } catch (const std::invalid_argument& e) {
            const std::string message = e.what();
            EXPECT_NE(message.find("unknown method '" + std::string(bad) + "'"), std::string::npos) << message;
            EXPECT_NE(message.find("valid: path, vrl, vrl-lightcuts, vrl-stochastic, vpl, vpl-lightcuts"),
                      std::string::npos)
                << message;
        }
    }
    // A long name is cut in the message, not echoed whole.
    const std::string longName(10000, 'x');
    try {
        (void)parseRenderMethod(longName);
        ADD_FAILURE() << "a 10000-character name was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_LT(std::string(e.what()).size(), 200u);
    }
    EXPECT_THROW((void)methodTraits(RenderMethod(6)), std::invalid_argument);
    EXPECT_THROW((void)methodTraits(RenderMethod(-1)), std::invalid_argument);
}

TEST(RenderMethodTable, WhichMethodsReadEachSetting) {
    EXPECT_EQ(methodsReading(&MethodReads::lightCount), "the virtual-light methods");
    EXPECT_EQ(methodsReading(&MethodReads::transports), "the virtual-light methods");
    EXPECT_EQ(methodsReading(&MethodReads::cutError), "vrl-lightcuts and vpl-lightcuts");
    EXPECT_EQ(methodsReading(&MethodReads::vrlClusterBounds), "vrl-lightcuts");
    EXPECT_EQ(methodsReading(&MethodReads::partitionSize), "vrl-lightcuts, vrl-stochastic and vpl-lightcuts");
    EXPECT_EQ(methodsReading(&MethodReads::stochasticCutSize), "vrl-stochastic");
    EXPECT_EQ(methodsReading(&MethodReads::vrlSets), "vrl-stochastic");
    EXPECT_EQ(methodsReading(&MethodReads::vrlSamples), "vrl, vrl-lightcuts and vrl-stochastic");
    EXPECT_EQ(methodsReading(&MethodReads::vplDistanceSamples), "vpl and vpl-lightcuts");
    EXPECT_EQ(methodsReading(&MethodReads::shadingPoints), "vrl, vrl-lightcuts, vpl and vpl-lightcuts");
    EXPECT_EQ(methodsReading(&MethodReads::surfaceVplLimit), "vrl and vrl-lightcuts");
}

TEST(RenderMethodTable, PredicatesAndCounterLayers) {
    for (RenderMethod m : kRenderMethods) {
        const MethodTraits& t = methodTraits(m);
        EXPECT_EQ(usesVirtualLights(m), m != RenderMethod::Path) << t.name;
        EXPECT_EQ(usesVpls(m), m == RenderMethod::Vpl || m == RenderMethod::VplLightcuts) << t.name;
        EXPECT_EQ(usesLightTree(m), m == RenderMethod::VrlLightcuts || m == RenderMethod::VrlStochastic ||
                                        m == RenderMethod::VplLightcuts)
            << t.name;
    }
    const PartEstimators& lightcuts = methodTraits(RenderMethod::VrlLightcuts).estimators;
    EXPECT_EQ(counterLayers(lightcuts.multiple), &kCutLayerNames);
    EXPECT_EQ(counterLayers(lightcuts.mediumSurface), &kSurfaceCutLayerNames);
    EXPECT_EQ(counterLayers(lightcuts.surfaceVpls), &kSurfaceVplCutLayerNames);
    const PartEstimators& stochastic = methodTraits(RenderMethod::VrlStochastic).estimators;
    EXPECT_EQ(counterLayers(stochastic.multiple), &kStochasticLayerNames);
    EXPECT_EQ(counterLayers(stochastic.mediumSurface), &kSurfaceStochasticLayerNames);
    EXPECT_EQ(counterLayers(stochastic.surfaceVpls), nullptr);
    const PartEstimators& plain = methodTraits(RenderMethod::Vrl).estimators;
    EXPECT_EQ(counterLayers(plain.multiple), nullptr);
    EXPECT_EQ(counterLayers(plain.mediumSurface), nullptr);
    EXPECT_EQ(counterLayers(methodTraits(RenderMethod::VplLightcuts).estimators.multiple), &kCutLayerNames);
}

}  // namespace
}  // namespace vrl
