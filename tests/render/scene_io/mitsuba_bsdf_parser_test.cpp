// Tests for the bsdf and texture part of the Mitsuba XML parser
// (render/scene_io/mitsuba/mitsuba_bsdf_parser.cpp, with the named IORs and
// conductor presets of ior_table.cpp and spectrum.cpp): every bsdf plugin's
// defaults and parameters, twosided and bumpmap wrappers, bitmap and scale
// textures, and which textures are stored.
#include "tests/render/scene_io/mitsuba_test_support.h"

#include "render/scene_io/mitsuba/mitsuba_parser.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace vrl {
namespace {

using mitsuba_test::sceneXml;
using mitsuba_test::parse;
using mitsuba_test::errorOf;
using mitsuba_test::mentions;
using mitsuba_test::expectNear;
using mitsuba_test::SceneFiles;

// ---------------------------------------------------------------- bsdfs and refs

TEST(MitsubaParser, BsdfKindsAndTwoSided) {
    const SceneDescription scene = parse({
        "<bsdf type=\"diffuse\" id=\"red\"><rgb name=\"reflectance\" value=\"0.8, 0.1, 0.1\"/></bsdf>",
        "<bsdf type=\"twosided\" id=\"wall\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" "
        "value=\"0.3\"/></bsdf></bsdf>",
        "<shape type=\"rectangle\"><ref id=\"red\"/></shape>",
        "<shape type=\"rectangle\"><ref name=\"bsdf\" id=\"wall\"/></shape>",
        "<shape type=\"rectangle\"><bsdf type=\"twosided\"><ref id=\"red\"/></bsdf></shape>",
        "<shape type=\"rectangle\"><bsdf type=\"null\"/></shape>",
        "<shape type=\"rectangle\"/>",
    });
    ASSERT_EQ(scene.shapes.size(), 5u);
    EXPECT_EQ(scene.shapes[0].bsdf->kind, BsdfDescription::Kind::Diffuse);
    expectNear(scene.shapes[0].bsdf->reflectance.value, Rgb(0.8f, 0.1f, 0.1f));
    EXPECT_FALSE(scene.shapes[0].bsdf->twoSided);
    expectNear(scene.shapes[1].bsdf->reflectance.value, Rgb(0.3f));
    EXPECT_TRUE(scene.shapes[1].bsdf->twoSided);
    expectNear(scene.shapes[2].bsdf->reflectance.value, Rgb(0.8f, 0.1f, 0.1f));
    EXPECT_TRUE(scene.shapes[2].bsdf->twoSided);
    EXPECT_EQ(scene.shapes[3].bsdf->kind, BsdfDescription::Kind::Null);
    EXPECT_FALSE(scene.shapes[4].bsdf.has_value());
}

// ---------------------------------------------------------------- bsdf plugins

// The bsdf of the first shape of a scene whose body is `bsdf` inside a <shape>.
BsdfDescription shapeBsdf(const std::string& bsdf) {
    const SceneDescription scene = parse({"<shape type=\"cube\">" + bsdf + "</shape>"});
    return scene.shapes.at(0).bsdf.value();
}

void expectConstant(const ColorDescription& color, const Rgb& value) {
    EXPECT_EQ(color.texture, -1);
    expectNear(color.value, value);
}

TEST(MitsubaParserBsdf, DielectricDefaultsAreMitsubas) {
    const BsdfDescription glass = shapeBsdf("<bsdf type=\"dielectric\"/>");
    EXPECT_EQ(glass.kind, BsdfDescription::Kind::Dielectric);
    EXPECT_FLOAT_EQ(glass.intIOR, 1.5046f);    // bk7
    EXPECT_FLOAT_EQ(glass.extIOR, 1.000277f);  // air
    expectConstant(glass.specularReflectance, Rgb(1.0f));
    expectConstant(glass.specularTransmittance, Rgb(1.0f));
    EXPECT_FALSE(glass.twoSided);
}

TEST(MitsubaParserBsdf, DielectricExplicitValuesAndNamedIors) {
    const BsdfDescription glass = shapeBsdf(
        "<bsdf type=\"dielectric\"><string name=\"intIOR\" value=\"Water\"/><float name=\"extIOR\" value=\"1.1\"/>"
        "<rgb name=\"specularReflectance\" value=\"0.9\"/><rgb name=\"specularTransmittance\" value=\"0.8, 0.7, "
        "0.6\"/></bsdf>");
    EXPECT_FLOAT_EQ(glass.intIOR, 1.333f);
    EXPECT_FLOAT_EQ(glass.extIOR, 1.1f);
    expectConstant(glass.specularReflectance, Rgb(0.9f));
    expectConstant(glass.specularTransmittance, Rgb(0.8f, 0.7f, 0.6f));
}

TEST(MitsubaParserBsdf, EveryNamedIorHasMitsubasValue) {
    const std::pair<std::string, float> table[] = {
        {"vacuum", 1.0f},      {"helium", 1.000036f},        {"hydrogen", 1.000132f},
        {"air", 1.000277f},    {"carbon dioxide", 1.00045f}, {"water", 1.3330f},
        {"acetone", 1.36f},    {"ethanol", 1.361f},          {"carbon tetrachloride", 1.461f},
        {"glycerol", 1.4729f}, {"benzene", 1.501f},          {"silicone oil", 1.52045f},
        {"bromine", 1.661f},   {"water ice", 1.31f},         {"fused quartz", 1.458f},
        {"pyrex", 1.470f},     {"acrylic glass", 1.49f},     {"polypropylene", 1.49f},
        {"bk7", 1.5046f},      {"sodium chloride", 1.544f},  {"amber", 1.55f},
        {"pet", 1.5750f},      {"diamond", 2.419f},
    };
    for (const auto& [name, value] : table) {
        const BsdfDescription bsdf = shapeBsdf("<bsdf type=\"roughdielectric\"><string name=\"extIOR\" value=\"" +
                                               name + "\"/><float name=\"intIOR\" value=\"3\"/></bsdf>");
        EXPECT_FLOAT_EQ(bsdf.extIOR, value) << name;
    }
}

TEST(MitsubaParserBsdf, RoughDielectricDistributionsAndRoughness) {
    const BsdfDescription byDefault = shapeBsdf("<bsdf type=\"roughdielectric\"/>");
    EXPECT_EQ(byDefault.kind, BsdfDescription::Kind::RoughDielectric);
    EXPECT_EQ(byDefault.distribution, MicrofacetKind::Beckmann);
    EXPECT_FLOAT_EQ(byDefault.alphaU, 0.1f);
    EXPECT_FLOAT_EQ(byDefault.alphaV, 0.1f);
    const BsdfDescription ggx = shapeBsdf(
        "<bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"GGX\"/>"
        "<float name=\"alphaU\" value=\"0.05\"/><float name=\"alphaV\" value=\"0.3\"/></bsdf>");
    EXPECT_EQ(ggx.distribution, MicrofacetKind::GGX);
    EXPECT_FLOAT_EQ(ggx.alphaU, 0.05f);
    EXPECT_FLOAT_EQ(ggx.alphaV, 0.3f);
    for (const std::string name : {"phong", "as"}) {  // "as": Mitsuba 0.5's alias
        const BsdfDescription phong =
            shapeBsdf("<bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"" + name +
                      "\"/><float name=\"alpha\" value=\"0.2\"/></bsdf>");
        EXPECT_EQ(phong.distribution, MicrofacetKind::Phong) << name;
        EXPECT_FLOAT_EQ(phong.alphaU, 0.2f);
        EXPECT_FLOAT_EQ(phong.alphaV, 0.2f);
    }
}

TEST(MitsubaParserBsdf, ConductorDefaultsToCopper) {
    const BsdfDescription metal = shapeBsdf("<bsdf type=\"conductor\"/>");
    EXPECT_EQ(metal.kind, BsdfDescription::Kind::Conductor);
    const BsdfDescription defaults;
    expectNear(metal.eta, defaults.eta);
    expectNear(metal.k, defaults.k);
    expectNear(metal.eta, Rgb(0.200438f, 0.924033f, 1.10221f));
    expectNear(metal.k, Rgb(3.91295f, 2.45285f, 2.14219f));
    EXPECT_FLOAT_EQ(metal.extEta, 1.000277f);
    expectConstant(metal.specularReflectance, Rgb(1.0f));
}

TEST(MitsubaParserBsdf, ConductorPresets) {
    struct Preset {
        std::string name;
        Rgb eta, k;
    };
    // Mitsuba's data/ior spectra in linear sRGB (the staircase scene spells out Au and Al).
    const Preset presets[] = {
        {"none", Rgb(0.0f), Rgb(1.0f)},
        {"Cu", Rgb(0.200438f, 0.924033f, 1.10221f), Rgb(3.91295f, 2.45285f, 2.14219f)},
        {"Au", Rgb(0.143119f, 0.374957f, 1.44248f), Rgb(3.98316f, 2.38572f, 1.60322f)},
        {"Ag", Rgb(0.155265f, 0.116723f, 0.138381f), Rgb(4.82834f, 3.12225f, 2.14695f)},
        {"Al", Rgb(1.65746f, 0.880369f, 0.521229f), Rgb(9.22387f, 6.26952f, 4.837f)},
        {"Cr", Rgb(4.36968f, 2.9167f, 1.6547f), Rgb(5.20643f, 4.23136f, 3.75495f)},
    };
    for (const Preset& preset : presets) {
        const BsdfDescription metal =
            shapeBsdf("<bsdf type=\"roughconductor\"><string name=\"material\" value=\"" + preset.name + "\"/></bsdf>");
        SCOPED_TRACE(preset.name);
        EXPECT_EQ(metal.kind, BsdfDescription::Kind::RoughConductor);
        expectNear(metal.eta, preset.eta);
        expectNear(metal.k, preset.k);
    }
    EXPECT_NO_THROW(shapeBsdf("<bsdf type=\"conductor\"><string name=\"material\" value=\"NONE\"/></bsdf>"));
}

TEST(MitsubaParserBsdf, ConductorExplicitEtaKAndExtEta) {
    const BsdfDescription metal = shapeBsdf(
        "<bsdf type=\"roughconductor\"><string name=\"material\" value=\"Au\"/>"
        "<rgb name=\"eta\" value=\"2.8656, 2.11918, 1.94008\"/><rgb name=\"k\" value=\"3.03233 2.05611 1.61629\"/>"
        "<string name=\"extEta\" value=\"water\"/><rgb name=\"specularReflectance\" value=\"0.5\"/>"
        "<string name=\"distribution\" value=\"ggx\"/><float name=\"alpha\" value=\"0.3\"/></bsdf>");
    expectNear(metal.eta, Rgb(2.8656f, 2.11918f, 1.94008f));  // eta and k override the preset
    expectNear(metal.k, Rgb(3.03233f, 2.05611f, 1.61629f));
    EXPECT_FLOAT_EQ(metal.extEta, 1.333f);  // kept apart: the model divides eta and k by it
    expectConstant(metal.specularReflectance, Rgb(0.5f));
    EXPECT_EQ(metal.distribution, MicrofacetKind::GGX);
    EXPECT_FLOAT_EQ(metal.alphaU, 0.3f);
}

TEST(MitsubaParserBsdf, PlasticDefaultsAndValues) {
    const BsdfDescription byDefault = shapeBsdf("<bsdf type=\"plastic\"/>");
    EXPECT_EQ(byDefault.kind, BsdfDescription::Kind::Plastic);
    EXPECT_FLOAT_EQ(byDefault.intIOR, 1.49f);  // polypropylene
    EXPECT_FLOAT_EQ(byDefault.extIOR, 1.000277f);
    expectConstant(byDefault.reflectance, Rgb(0.5f));
    expectConstant(byDefault.specularReflectance, Rgb(1.0f));
    EXPECT_FALSE(byDefault.nonlinear);
    const BsdfDescription rough = shapeBsdf(
        "<bsdf type=\"roughplastic\"><float name=\"alpha\" value=\"0.2\"/><string name=\"distribution\" "
        "value=\"ggx\"/><float name=\"intIOR\" value=\"1.5\"/><float name=\"extIOR\" value=\"1\"/>"
        "<boolean name=\"nonlinear\" value=\"true\"/><rgb name=\"diffuseReflectance\" value=\"0.578596\"/>"
        "<spectrum name=\"specularReflectance\" value=\"0.9\"/></bsdf>");
    EXPECT_EQ(rough.kind, BsdfDescription::Kind::RoughPlastic);
    EXPECT_FLOAT_EQ(rough.intIOR, 1.5f);
    EXPECT_FLOAT_EQ(rough.extIOR, 1.0f);
    EXPECT_TRUE(rough.nonlinear);
    EXPECT_EQ(rough.distribution, MicrofacetKind::GGX);
    EXPECT_FLOAT_EQ(rough.alphaU, 0.2f);
    EXPECT_FLOAT_EQ(rough.alphaV, 0.2f);
    expectConstant(rough.reflectance, Rgb(0.578596f));
    expectConstant(rough.specularReflectance, Rgb(0.9f));
}

TEST(MitsubaParserBsdf, WardDefaultsAndValues) {
    const BsdfDescription byDefault = shapeBsdf("<bsdf type=\"ward\"/>");
    EXPECT_EQ(byDefault.kind, BsdfDescription::Kind::Ward);
    EXPECT_EQ(byDefault.wardVariant, BsdfDescription::WardVariant::Balanced);
    EXPECT_FLOAT_EQ(byDefault.alphaU, 0.1f);
    EXPECT_FLOAT_EQ(byDefault.alphaV, 0.1f);
    expectConstant(byDefault.reflectance, Rgb(0.5f));
    expectConstant(byDefault.specularReflectance, Rgb(0.2f));
    const BsdfDescription lamp = shapeBsdf(
        "<bsdf type=\"ward\"><string name=\"variant\" value=\"ward-duer\"/><float name=\"alpha\" value=\"0.4\"/>"
        "<float name=\"alphaV\" value=\"0.6\"/><spectrum name=\"diffuseReflectance\" value=\"0\"/>"
        "<rgb name=\"specularReflectance\" value=\"0.61600 0.47520 0.35200\"/></bsdf>");
    EXPECT_EQ(lamp.wardVariant, BsdfDescription::WardVariant::WardDuer);
    EXPECT_FLOAT_EQ(lamp.alphaU, 0.4f);  // from alpha
    EXPECT_FLOAT_EQ(lamp.alphaV, 0.6f);  // alphaV overrides alpha
    expectConstant(lamp.reflectance, Rgb(0.0f));
    expectConstant(lamp.specularReflectance, Rgb(0.616f, 0.4752f, 0.352f));
    EXPECT_EQ(shapeBsdf("<bsdf type=\"ward\"><string name=\"variant\" value=\"ward\"/></bsdf>").wardVariant,
              BsdfDescription::WardVariant::Ward);
}

TEST(MitsubaParserBsdf, TwoSidedKeepsTheNestedModel) {
    const BsdfDescription metal = shapeBsdf(
        "<bsdf type=\"twosided\"><bsdf type=\"conductor\"><string name=\"material\" value=\"Au\"/>"
        "</bsdf></bsdf>");
    EXPECT_EQ(metal.kind, BsdfDescription::Kind::Conductor);
    EXPECT_TRUE(metal.twoSided);
    expectNear(metal.eta, Rgb(0.143119f, 0.374957f, 1.44248f));
}

TEST(MitsubaParserBsdf, NullBsdf) { EXPECT_EQ(shapeBsdf("<bsdf type=\"null\"/>").kind, BsdfDescription::Kind::Null); }

TEST(MitsubaParserBsdf, UnknownTypeListsEveryValidType) {
    const std::string message = errorOf(sceneXml({"<bsdf type=\"velvet\" id=\"v\"/>"}));
    EXPECT_TRUE(mentions(message, {"bad.xml:2:", "<bsdf type=\"velvet\" id=\"v\">", "'velvet'", "diffuse", "dielectric",
                                   "roughdielectric", "conductor", "roughconductor", "plastic", "roughplastic", "ward",
                                   "twosided", "bumpmap", "null"}));
}

TEST(MitsubaParserBsdf, SampleVisibleIsAcceptedAndReported) {
    const SceneDescription scene = parse({
        "<bsdf type=\"roughconductor\" id=\"a\"><boolean name=\"sampleVisible\" value=\"false\"/></bsdf>",
        "<bsdf type=\"roughconductor\" id=\"b\"><boolean name=\"sampleVisible\" value=\"true\"/></bsdf>",
    });
    ASSERT_EQ(scene.ignored.size(), 1u);
    EXPECT_TRUE(mentions(scene.ignored[0], {"roughconductor", "sampleVisible"}));
}

// ---------------------------------------------------------------- textures

TEST(MitsubaParserTexture, NestedBitmapWithDefaults) {
    const SceneFiles files({"textures/wood.jpg"});
    const SceneDescription scene = files.parse({
        "<shape type=\"cube\"><bsdf type=\"diffuse\">",
        "  <texture name=\"reflectance\" type=\"bitmap\"><string name=\"filename\" value=\"textures/wood.jpg\"/>",
        "  </texture>",
        "</bsdf></shape>",
    });
    ASSERT_EQ(scene.textures.size(), 1u);
    const TextureDescription& texture = scene.textures[0];
    EXPECT_EQ(texture.filename, files / "textures/wood.jpg");
    EXPECT_EQ(texture.wrapU, TextureDescription::Wrap::Repeat);
    EXPECT_EQ(texture.wrapV, TextureDescription::Wrap::Repeat);
    EXPECT_FLOAT_EQ(texture.uscale, 1.0f);
    EXPECT_FLOAT_EQ(texture.vscale, 1.0f);
    EXPECT_FLOAT_EQ(texture.uoffset, 0.0f);
    EXPECT_FLOAT_EQ(texture.voffset, 0.0f);
    EXPECT_FALSE(texture.gamma.has_value());
    EXPECT_EQ(texture.where.line, 3);
    const ColorDescription& reflectance = scene.shapes.at(0).bsdf->reflectance;
    EXPECT_EQ(reflectance.texture, 0);
    expectNear(reflectance.value, Rgb(1.0f));
}

TEST(MitsubaParserTexture, BitmapParameters) {
    const SceneFiles files({"a.png"});
    const SceneDescription scene = files.parse({
        "<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"a.png\"/>",
        "  <string name=\"wrapMode\" value=\"clamp\"/><string name=\"wrapModeV\" value=\"black\"/>",
        "  <float name=\"gamma\" value=\"-1\"/><float name=\"uvscale\" value=\"4\"/><float name=\"vscale\" "
        "value=\"2\"/>",
        "  <float name=\"uoffset\" value=\"0.25\"/><float name=\"voffset\" value=\"-0.5\"/>",
        "  <string name=\"channel\" value=\"rgb\"/><string name=\"filterType\" value=\"ewa\"/>",
        "  <float name=\"maxAnisotropy\" value=\"8\"/><boolean name=\"cache\" value=\"false\"/>",
        "</texture>",
        "<bsdf type=\"diffuse\" id=\"d\"><ref name=\"reflectance\" id=\"t\"/></bsdf>",
    });
    ASSERT_EQ(scene.textures.size(), 1u);
    const TextureDescription& texture = scene.textures[0];
    EXPECT_EQ(texture.wrapU, TextureDescription::Wrap::Clamp);
    EXPECT_EQ(texture.wrapV, TextureDescription::Wrap::Zero);
    ASSERT_TRUE(texture.gamma.has_value());
    EXPECT_FLOAT_EQ(*texture.gamma, -1.0f);
    EXPECT_FLOAT_EQ(texture.uscale, 4.0f);  // from uvscale
    EXPECT_FLOAT_EQ(texture.vscale, 2.0f);  // vscale overrides uvscale
    EXPECT_FLOAT_EQ(texture.uoffset, 0.25f);
    EXPECT_FLOAT_EQ(texture.voffset, -0.5f);
    ASSERT_EQ(scene.ignored.size(), 1u);
    EXPECT_TRUE(mentions(scene.ignored[0], {"texture 'bitmap'", "filterType", "maxAnisotropy", "cache"}));
}

TEST(MitsubaParserTexture, GammaZeroMeansAutomatic) {
    const SceneFiles files({"a.png"});
    const SceneDescription scene = files.parse({
        "<bsdf type=\"diffuse\" id=\"d\"><texture name=\"reflectance\" type=\"bitmap\">",
        "<string name=\"filename\" value=\"a.png\"/><float name=\"gamma\" value=\"0\"/></texture></bsdf>",
    });
    ASSERT_EQ(scene.textures.size(), 1u);
    EXPECT_FALSE(scene.textures[0].gamma.has_value());
}

TEST(MitsubaParserTexture, ReferencedTexturesAreGlobalAndStoredOnce) {
    const SceneFiles files({"wood.jpg", "fabric.jpg"});
    const SceneDescription scene = files.parse({
        "<texture type=\"bitmap\" id=\"wood\"><string name=\"filename\" value=\"wood.jpg\"/></texture>",
        "<bsdf type=\"plastic\" id=\"floor\"><ref name=\"diffuseReflectance\" id=\"wood\"/></bsdf>",
        "<bsdf type=\"twosided\" id=\"stairs\"><bsdf type=\"roughplastic\">",
        "  <ref name=\"diffuseReflectance\" id=\"wood\"/>",
        "  <texture name=\"specularReflectance\" type=\"bitmap\" id=\"cloth\">",
        "    <string name=\"filename\" value=\"fabric.jpg\"/></texture>",
        "</bsdf></bsdf>",
        // The same file declared again with the same mapping is shared.
        "<bsdf type=\"ward\" id=\"w\"><texture name=\"specularReflectance\" type=\"bitmap\">",
        "  <string name=\"filename\" value=\"wood.jpg\"/></texture><ref name=\"diffuseReflectance\" id=\"cloth\"/>",
        "</bsdf>",
        "<shape type=\"cube\"><ref id=\"floor\"/></shape>",
        "<shape type=\"cube\"><ref id=\"stairs\"/></shape>",
        "<shape type=\"cube\"><ref id=\"w\"/></shape>",
    });
    ASSERT_EQ(scene.textures.size(), 2u);
    EXPECT_EQ(scene.textures[0].filename, files / "wood.jpg");
    EXPECT_EQ(scene.textures[1].filename, files / "fabric.jpg");
    EXPECT_EQ(scene.shapes[0].bsdf->reflectance.texture, 0);
    EXPECT_EQ(scene.shapes[1].bsdf->reflectance.texture, 0);
    EXPECT_EQ(scene.shapes[1].bsdf->specularReflectance.texture, 1);
    EXPECT_TRUE(scene.shapes[1].bsdf->twoSided);
    EXPECT_EQ(scene.shapes[2].bsdf->specularReflectance.texture, 0);
    EXPECT_EQ(scene.shapes[2].bsdf->reflectance.texture, 1);
}

TEST(MitsubaParserTexture, DifferentMappingsOfOneFileAreDistinct) {
    const SceneFiles files({"a.png"});
    const SceneDescription scene = files.parse({
        "<bsdf type=\"plastic\" id=\"p\">",
        "<texture name=\"diffuseReflectance\" type=\"bitmap\"><string name=\"filename\" value=\"a.png\"/></texture>",
        "<texture name=\"specularReflectance\" type=\"bitmap\"><string name=\"filename\" value=\"a.png\"/>",
        "<float name=\"uscale\" value=\"2\"/></texture>",
        "</bsdf>",
    });
    EXPECT_EQ(scene.textures.size(), 2u);
}

TEST(MitsubaParserTexture, ScaleTexture) {
    const SceneFiles files({"a.png"});
    const SceneDescription scene = files.parse({
        "<texture type=\"bitmap\" id=\"base\"><string name=\"filename\" value=\"a.png\"/></texture>",
        "<shape type=\"cube\"><bsdf type=\"diffuse\"><texture name=\"reflectance\" type=\"scale\">",
        "  <rgb name=\"scale\" value=\"0.5, 0.25, 1\"/>",
        "  <texture type=\"scale\"><float name=\"scale\" value=\"0.5\"/><ref id=\"base\"/></texture>",
        "</texture></bsdf></shape>",
    });
    ASSERT_EQ(scene.textures.size(), 1u);
    const ColorDescription& reflectance = scene.shapes.at(0).bsdf->reflectance;
    EXPECT_EQ(reflectance.texture, 0);
    expectNear(reflectance.value, Rgb(0.25f, 0.125f, 0.5f));
}

TEST(MitsubaParserTexture, UnusedTexturesAreNotStored) {
    const SceneFiles files({"a.png"});
    const SceneDescription scene =
        files.parse({"<texture type=\"bitmap\" id=\"unused\"><string name=\"filename\" value=\"a.png\"/></texture>"});
    EXPECT_TRUE(scene.textures.empty());
}

TEST(MitsubaParserTexture, TextureFilesAreReportedAndConfined) {
    const SceneFiles files({"a.png"});
    std::vector<std::filesystem::path> referenced;
    ParseOptions options;
    options.onFileReferenced = [&](const std::filesystem::path& path) { referenced.push_back(path); };
    options.confineTo = files.directory();
    files.parse({"<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"a.png\"/></texture>"}, options);
    ASSERT_EQ(referenced.size(), 1u);
    EXPECT_EQ(referenced[0], files / "a.png");
    options.confineTo = files.directory() / "elsewhere";
    try {
        files.parse({"<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"a.png\"/></texture>"},
                    options);
        ADD_FAILURE() << "expected a SceneError";
    } catch (const SceneError& e) {
        EXPECT_TRUE(mentions(e.what(), {"a.png", "outside the scene bundle"}));
    }
}

TEST(MitsubaParserTexture, BumpMapIsApproximatedByItsNestedBsdf) {
    const SceneFiles files({"bump.png"});
    const SceneDescription scene = files.parse({
        "<shape type=\"cube\">", "  <bsdf type=\"bumpmap\">",
        "    <texture name=\"map\" type=\"bitmap\"><string name=\"filename\" value=\"bump.png\"/></texture>",
        "    <bsdf type=\"roughconductor\" id=\"metal\"><string name=\"material\" value=\"Al\"/></bsdf>", "  </bsdf>",
        "</shape>",
        "<shape type=\"cube\"><ref id=\"metal\"/></shape>",  // the nested id names the bsdf without the bump map
    });
    ASSERT_EQ(scene.shapes.size(), 2u);
    const BsdfDescription& bumped = *scene.shapes[0].bsdf;
    EXPECT_EQ(bumped.kind, BsdfDescription::Kind::RoughConductor);
    expectNear(bumped.eta, Rgb(1.65746f, 0.880369f, 0.521229f));
    ASSERT_EQ(bumped.approximations.size(), 1u);
    EXPECT_TRUE(
        mentions(bumped.approximations[0], {"bumpmap at test.xml:3", "bump map ignored", "unperturbed normal"}));
    ASSERT_EQ(scene.approximations.size(), 1u);
    EXPECT_EQ(scene.approximations[0], bumped.approximations[0]);
    EXPECT_EQ(scene.shapes[1].bsdf->kind, BsdfDescription::Kind::RoughConductor);
    EXPECT_TRUE(scene.shapes[1].bsdf->approximations.empty());
    EXPECT_TRUE(scene.textures.empty());  // the displacement map is checked, not stored
}

TEST(MitsubaParserTexture, UnusedBumpMapAddsNoSceneApproximation) {
    const SceneFiles files({"bump.png"});
    const SceneDescription scene = files.parse({
        "<texture type=\"bitmap\" id=\"bumps\"><string name=\"filename\" value=\"bump.png\"/></texture>",
        "<bsdf type=\"bumpmap\" id=\"bumpy\"><ref id=\"bumps\"/>",
        "  <bsdf type=\"twosided\"><bsdf type=\"diffuse\"/></bsdf></bsdf>",
        "<bsdf type=\"twosided\" id=\"wrapped\"><ref id=\"bumpy\"/></bsdf>",
    });
    EXPECT_TRUE(scene.approximations.empty());
    const SceneDescription used = files.parse({
        "<texture type=\"bitmap\" id=\"bumps\"><string name=\"filename\" value=\"bump.png\"/></texture>",
        "<bsdf type=\"bumpmap\" id=\"bumpy\"><ref id=\"bumps\"/><bsdf type=\"diffuse\"/></bsdf>",
        "<shape type=\"cube\"><ref id=\"bumpy\"/></shape>",
        "<shape type=\"cube\"><bsdf type=\"twosided\"><ref id=\"bumpy\"/></bsdf></shape>",
    });
    EXPECT_EQ(used.approximations.size(), 1u);  // one line although two shapes use it
    EXPECT_TRUE(used.shapes[1].bsdf->twoSided);
    EXPECT_EQ(used.shapes[1].bsdf->approximations.size(), 1u);
}

}  // namespace
}  // namespace vrl
