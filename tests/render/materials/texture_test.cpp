// Tests of render/texture.h (loading, linearisation, orientation, bilinear lookup,
// wrap modes, errors) and render/preview_image.h. Test images are written with
// OpenImageIO into a per-test temporary directory.
#include "render/image/preview_image.h"
#include "render/materials/texture.h"
#include "tests/support/temp_dir.h"

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

namespace vrl {
namespace {

namespace fs = std::filesystem;
using Wrap = TextureDescription::Wrap;

float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

void expectRgbNear(const Rgb& expected, const Rgb& actual, float tolerance, const std::string& what) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(expected[c], actual[c], tolerance) << what << ", channel " << c;
}

class TextureTest : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
        dir_ = test::freshDirectory("vrl_texture_test_" + test);
    }
    void TearDown() override { fs::remove_all(dir_); }

    // Writes `data` (row 0 at the top) with OpenImageIO; tiled if tileSize > 0.
    template <typename T>
    fs::path write(const std::string& name, int width, int height, int channels, OIIO::TypeDesc format,
                   const std::vector<T>& data, int tileSize = 0) {
        const fs::path path = dir_ / name;
        auto out = OIIO::ImageOutput::create(path.string());
        if (!out) {
            ADD_FAILURE() << OIIO::geterror();
            return path;
        }
        OIIO::ImageSpec spec(width, height, channels, format);
        if (tileSize > 0) spec.tile_width = spec.tile_height = tileSize;
        if (!out->open(path.string(), spec)) {
            ADD_FAILURE() << out->geterror();
            return path;
        }
        EXPECT_TRUE(out->write_image(format, data.data())) << out->geterror();
        EXPECT_TRUE(out->close()) << out->geterror();
        return path;
    }

    static TextureDescription describe(const fs::path& file, Wrap wrap = Wrap::Clamp) {
        TextureDescription d;
        d.filename = file;
        d.wrapU = d.wrapV = wrap;
        d.where = SourceLocation{"scene.xml", 12, "<texture type=\"bitmap\">"};
        return d;
    }

    fs::path dir_;
};

// Texel centre of texel (x, y) of a width x height texture, y counted from the bottom.
Vec2 centre(int x, int y, int width, int height) {
    return {(float(x) + 0.5f) / float(width), (float(y) + 0.5f) / float(height)};
}

TEST_F(TextureTest, EightBitPngIsSrgbDecoded) {
    const std::vector<uint8_t> data = {0, 128, 255, 64, 200, 10};  // 2 x 1, RGB
    const auto tex = Texture::load(describe(write("srgb.png", 2, 1, 3, OIIO::TypeDesc::UINT8, data)));
    ASSERT_EQ(tex->width(), 2);
    ASSERT_EQ(tex->height(), 1);
    const Rgb left = tex->eval(centre(0, 0, 2, 1));
    EXPECT_NEAR(left.x, 0.0f, 1e-6f);
    EXPECT_NEAR(left.y, 0.2158605f, 1e-4f);
    EXPECT_NEAR(left.z, 1.0f, 1e-6f);
    expectRgbNear(Rgb(srgbToLinear(64 / 255.0f), srgbToLinear(200 / 255.0f), srgbToLinear(10 / 255.0f)),
                  tex->eval(centre(1, 0, 2, 1)), 1e-6f, "right texel");
}

TEST_F(TextureTest, SixteenBitPngIsSrgbDecoded) {
    const std::vector<uint16_t> data = {0, 32768, 65535};
    const auto tex = Texture::load(describe(write("srgb16.png", 1, 1, 3, OIIO::TypeDesc::UINT16, data)));
    expectRgbNear(Rgb(0.0f, srgbToLinear(32768 / 65535.0f), 1.0f), tex->eval({0.5f, 0.5f}), 1e-6f, "16-bit");
}

TEST_F(TextureTest, FloatImagesAreLinear) {
    const std::vector<float> data = {0.3f, 2.5f, 0.0f, 1e-3f, 0.75f, 100.0f};
    for (const char* name : {"linear.exr", "linear.tif"}) {
        const auto tex = Texture::load(describe(write(name, 2, 1, 3, OIIO::TypeDesc::FLOAT, data)));
        expectRgbNear(Rgb(0.3f, 2.5f, 0.0f), tex->eval(centre(0, 0, 2, 1)), 1e-6f, name);
        expectRgbNear(Rgb(1e-3f, 0.75f, 100.0f), tex->eval(centre(1, 0, 2, 1)), 1e-5f, name);
    }
}

TEST_F(TextureTest, GreyReplicatesAndAlphaIsDropped) {
    const auto grey = Texture::load(describe(write("grey.png", 1, 1, 1, OIIO::TypeDesc::UINT8, std::vector<uint8_t>{128})));
    expectRgbNear(Rgb(0.2158605f), grey->eval({0.5f, 0.5f}), 1e-4f, "grey");
    const auto greyAlpha = Texture::load(
        describe(write("grey_alpha.png", 1, 1, 2, OIIO::TypeDesc::UINT8, std::vector<uint8_t>{255, 0})));
    expectRgbNear(Rgb(1.0f), greyAlpha->eval({0.5f, 0.5f}), 1e-6f, "grey + alpha");
    const auto rgba = Texture::load(
        describe(write("rgba.exr", 1, 1, 4, OIIO::TypeDesc::FLOAT, std::vector<float>{0.1f, 0.2f, 0.3f, 0.0f})));
    expectRgbNear(Rgb(0.1f, 0.2f, 0.3f), rgba->eval({0.5f, 0.5f}), 1e-6f, "rgba");
}

TEST_F(TextureTest, ExplicitGammaOverridesTheFileRule) {
    const fs::path png = write("g.png", 1, 1, 3, OIIO::TypeDesc::UINT8, std::vector<uint8_t>{128, 128, 128});
    TextureDescription d = describe(png);
    d.gamma = 1.0f;
    EXPECT_NEAR(Texture::load(d)->eval({0.5f, 0.5f}).x, 128 / 255.0f, 1e-6f);
    d.gamma = 2.2f;
    EXPECT_NEAR(Texture::load(d)->eval({0.5f, 0.5f}).x, std::pow(128 / 255.0f, 2.2f), 1e-6f);
    d.gamma = -1.0f;
    EXPECT_NEAR(Texture::load(d)->eval({0.5f, 0.5f}).x, 0.2158605f, 1e-4f);

    TextureDescription f = describe(write("g.exr", 1, 1, 3, OIIO::TypeDesc::FLOAT, std::vector<float>{0.5f, 0.5f, 0.5f}));
    f.gamma = -1.0f;
    EXPECT_NEAR(Texture::load(f)->eval({0.5f, 0.5f}).x, srgbToLinear(0.5f), 1e-6f);
    f.gamma = -2.0f;
    EXPECT_THROW(Texture::load(f), SceneError);
}

// v = 0 is the bottom row of the image file (OIIO's last row), for scanline and tiled files.
TEST_F(TextureTest, VZeroIsTheBottomRow) {
    const std::vector<float> topRedBottomBlue = {1, 0, 0, 0, 0, 1};  // 1 x 2, top row first
    const fs::path scan = write("rows.exr", 1, 2, 3, OIIO::TypeDesc::FLOAT, topRedBottomBlue);
    constexpr int n = 32;  // 2 x 2 tiles of 16 x 16
    std::vector<float> tiled(n * n * 3, 0.0f);
    for (int x = 0; x < n; ++x) tiled[size_t(x) * 3] = 1.0f;                  // top row red
    for (int x = 0; x < n; ++x) tiled[size_t((n - 1) * n + x) * 3 + 2] = 1.0f;  // bottom row blue
    const fs::path tile = write("tiled.tif", n, n, 3, OIIO::TypeDesc::FLOAT, tiled, 16);
    for (const auto& [file, height] : {std::pair{scan, 2}, std::pair{tile, n}}) {
        const auto tex = Texture::load(describe(file));
        expectRgbNear(Rgb(0, 0, 1), tex->eval(centre(0, 0, tex->width(), height)), 1e-6f, file.string() + " bottom");
        expectRgbNear(Rgb(1, 0, 0), tex->eval(centre(0, height - 1, tex->width(), height)), 1e-6f,
                      file.string() + " top");
    }
    const Texture fromTexels(1, 2, {Rgb(1, 0, 0), Rgb(0, 0, 1)});  // row 0 at the top as well
    expectRgbNear(Rgb(0, 0, 1), fromTexels.eval({0.5f, 0.25f}), 1e-6f, "constructor bottom");
    expectRgbNear(Rgb(1, 0, 0), fromTexels.eval({0.5f, 0.75f}), 1e-6f, "constructor top");
}

TEST_F(TextureTest, BilinearBetweenTexelCentres) {
    TextureDescription d;
    d.wrapU = d.wrapV = Wrap::Clamp;
    // 2 x 2, top row (0, 1), bottom row (2, 3).
    const Texture tex(2, 2, {Rgb(0.0f), Rgb(1.0f), Rgb(2.0f), Rgb(3.0f)}, d);
    EXPECT_NEAR(tex.eval({0.25f, 0.25f}).x, 2.0f, 1e-6f);
    EXPECT_NEAR(tex.eval({0.75f, 0.75f}).x, 1.0f, 1e-6f);
    EXPECT_NEAR(tex.eval({0.5f, 0.25f}).x, 2.5f, 1e-6f);   // midpoint of the bottom row
    EXPECT_NEAR(tex.eval({0.25f, 0.5f}).x, 1.0f, 1e-6f);   // midpoint of the left column
    EXPECT_NEAR(tex.eval({0.5f, 0.5f}).x, 1.5f, 1e-6f);    // centre of all four
    EXPECT_NEAR(tex.eval({0.375f, 0.25f}).x, 2.25f, 1e-6f);  // a quarter of the way
    EXPECT_NEAR(tex.eval({0.0f, 0.0f}).x, 2.0f, 1e-6f);    // clamped corner
}

// A 3 x 1 row (0.1, 0.5, 0.9) looked up at the centres of texels outside it.
TEST_F(TextureTest, WrapModes) {
    const std::vector<Rgb> row = {Rgb(0.1f), Rgb(0.5f), Rgb(0.9f)};
    auto at = [&](Wrap wrap, int texel) {
        TextureDescription d;
        d.wrapU = wrap;
        d.wrapV = Wrap::Clamp;
        return Texture(3, 1, row, d).eval(centre(texel, 0, 3, 1)).x;
    };
    struct Case {
        Wrap wrap;
        int texel;
        float expected;
    };
    const Case cases[] = {
        {Wrap::Repeat, -1, 0.9f}, {Wrap::Repeat, -4, 0.9f}, {Wrap::Repeat, 3, 0.1f}, {Wrap::Repeat, 4, 0.5f},
        {Wrap::Mirror, -1, 0.1f}, {Wrap::Mirror, -2, 0.5f}, {Wrap::Mirror, 3, 0.9f}, {Wrap::Mirror, 5, 0.1f},
        {Wrap::Clamp, -2, 0.1f},  {Wrap::Clamp, 4, 0.9f},   {Wrap::Zero, -1, 0.0f},  {Wrap::Zero, 3, 0.0f},
        {Wrap::One, -1, 1.0f},    {Wrap::One, 3, 1.0f},     {Wrap::Zero, 1, 0.5f},   {Wrap::One, 1, 0.5f},
    };
    for (const Case& c : cases)
        EXPECT_NEAR(at(c.wrap, c.texel), c.expected, 1e-5f) << "wrap " << int(c.wrap) << ", texel " << c.texel;

    // Half-way between the outside and the first texel.
    TextureDescription zero;
    zero.wrapU = Wrap::Zero;
    EXPECT_NEAR(Texture(3, 1, row, zero).eval({0.0f, 0.5f}).x, 0.05f, 1e-6f);

    // wrapV acts on v alone: a 1 x 3 column, bottom texel 0.9.
    TextureDescription v;
    v.wrapU = Wrap::Zero;
    v.wrapV = Wrap::Repeat;
    const Texture column(1, 3, row, v);
    EXPECT_NEAR(column.eval(centre(0, -1, 1, 3)).x, 0.1f, 1e-5f);  // wraps to the top texel
    EXPECT_NEAR(column.eval(centre(-1, 0, 1, 3)).x, 0.0f, 1e-6f);

    // Far-away and non-finite coordinates stay finite and periodic.
    TextureDescription repeat;
    const Texture tiled(3, 1, row, repeat);
    EXPECT_NEAR(tiled.eval({1000.0f + 0.5f, 0.5f}).x, 0.5f, 1e-3f);
    EXPECT_TRUE(isFinite(tiled.eval({3e9f, -7e12f})));
    EXPECT_TRUE(isBlack(tiled.eval({std::numeric_limits<float>::quiet_NaN(), 0.5f})));
}

TEST_F(TextureTest, UvScaleAndOffset) {
    TextureDescription d;
    d.uscale = 2.0f;
    d.voffset = 0.5f;
    d.wrapU = Wrap::Repeat;
    d.wrapV = Wrap::Clamp;
    // 2 x 2, top row (0, 1), bottom row (2, 3).
    const Texture tex(2, 2, {Rgb(0.0f), Rgb(1.0f), Rgb(2.0f), Rgb(3.0f)}, d);
    // u' = 2 * 0.125 = 0.25 (left column), v' = 0.25 + 0.5 = 0.75 (top row).
    EXPECT_NEAR(tex.eval({0.125f, 0.25f}).x, 0.0f, 1e-6f);
    // u' = 2 * 0.625 = 1.25 -> 0.25 after repeating.
    EXPECT_NEAR(tex.eval({0.625f, 0.25f}).x, 0.0f, 1e-6f);
    EXPECT_NEAR(tex.eval({0.375f, 0.25f}).x, 1.0f, 1e-6f);
}

TEST_F(TextureTest, AverageIsTheMeanTexel) {
    const Texture tex(2, 2, {Rgb(0.0f, 1.0f, 2.0f), Rgb(1.0f), Rgb(2.0f), Rgb(3.0f, 0.0f, 0.0f)});
    expectRgbNear(Rgb(1.5f, 1.0f, 1.25f), tex.average(), 1e-6f, "average");
    const auto loaded = Texture::load(
        describe(write("avg.png", 2, 1, 1, OIIO::TypeDesc::UINT8, std::vector<uint8_t>{0, 255})));
    expectRgbNear(Rgb(0.5f), loaded->average(), 1e-6f, "loaded average");
    EXPECT_THROW(Texture(2, 2, std::vector<Rgb>(3)), std::invalid_argument);
}

TEST_F(TextureTest, ErrorsNameTheFileAndTheReason) {
    auto messageOf = [](const TextureDescription& d) -> std::string {
        try {
            Texture::load(d);
        } catch (const SceneError& e) {
            return e.what();
        }
        return "(no error)";
    };
    const fs::path missing = dir_ / "no_such_texture.png";
    const std::string notFound = messageOf(describe(missing));
    EXPECT_NE(notFound.find(missing.string()), std::string::npos) << notFound;
    EXPECT_NE(notFound.find("not found"), std::string::npos) << notFound;
    EXPECT_NE(notFound.find("scene.xml:12"), std::string::npos) << notFound;

    const fs::path garbage = dir_ / "garbage.png";
    std::ofstream(garbage, std::ios::binary) << "this is not a PNG file, just some bytes \x01\x02\x03";
    const std::string corrupt = messageOf(describe(garbage));
    EXPECT_NE(corrupt.find(garbage.string()), std::string::npos) << corrupt;
    EXPECT_EQ(corrupt.find("(no error)"), std::string::npos);

    const fs::path empty = dir_ / "empty.jpg";
    std::ofstream(empty, std::ios::binary).flush();
    EXPECT_THROW(Texture::load(describe(empty)), SceneError);
    EXPECT_THROW(Texture::load(describe(dir_)), SceneError);

    // A PNG cut in half: an error (or at worst a texture), never a crash.
    std::vector<uint8_t> noise(64 * 64 * 3);
    for (size_t i = 0; i < noise.size(); ++i) noise[i] = uint8_t(i * 7919 % 251);
    const fs::path whole = write("whole.png", 64, 64, 3, OIIO::TypeDesc::UINT8, noise);
    const auto size = fs::file_size(whole);
    fs::resize_file(whole, size / 2);
    EXPECT_THROW(Texture::load(describe(whole)), SceneError);
}

TEST_F(TextureTest, PreviewPngRoundTrip) {
    Image image(3, 2);
    image.at(0, 0) = Rgb(0.2158605f, 0.0f, 1.0f);
    image.at(1, 0) = Rgb(2.0f, -1.0f, std::numeric_limits<float>::quiet_NaN());
    image.at(2, 1) = Rgb(0.5f, 0.25f, 0.001f);
    const fs::path png = dir_ / "preview.png";
    writePreviewPng(image, png);
    auto in = OIIO::ImageInput::open(png.string());
    ASSERT_TRUE(in) << OIIO::geterror();
    ASSERT_EQ(in->spec().width, 3);
    ASSERT_EQ(in->spec().height, 2);
    ASSERT_EQ(in->spec().nchannels, 3);
    std::vector<uint8_t> bytes(3 * 2 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, bytes.data()));
    EXPECT_EQ(std::vector<int>(bytes.begin(), bytes.begin() + 6), (std::vector<int>{128, 0, 255, 255, 0, 0}));
    const size_t bottomRight = (1 * 3 + 2) * 3;
    EXPECT_EQ(bytes[bottomRight], 188);  // sRGB(0.5) = 0.7354
    EXPECT_FALSE(fs::exists(png.string() + ".tmp"));

    // One stop up: 0.5 becomes 1.
    writePreviewPng(image, png, 1.0f);
    in = OIIO::ImageInput::open(png.string());
    ASSERT_TRUE(in);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, bytes.data()));
    EXPECT_EQ(bytes[bottomRight], 255);

    EXPECT_THROW(writePreviewPng(Image(), png), std::invalid_argument);
    try {
        writePreviewPng(image, dir_ / "missing_dir" / "p.png");
        ADD_FAILURE() << "no error for a missing directory";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("missing_dir"), std::string::npos) << e.what();
    }
}

TEST(AutoExposure, MapsThe99thPercentileTo09) {
    Image flat(10, 10);
    for (size_t i = 0; i < flat.pixelCount(); ++i) flat[i] = Rgb(0.45f);
    EXPECT_NEAR(autoExposure(flat), 1.0f, 1e-5f);
    // One very bright pixel in 100 does not set the exposure.
    flat[0] = Rgb(1000.0f);
    EXPECT_NEAR(autoExposure(flat), 1.0f, 1e-5f);
    EXPECT_EQ(autoExposure(Image(4, 4)), 0.0f);
    EXPECT_EQ(autoExposure(Image()), 0.0f);
    Image sparse(10, 10);
    sparse[42] = Rgb(3.6f);  // below the percentile everything is black: use the maximum
    EXPECT_NEAR(autoExposure(sparse), -2.0f, 1e-5f);
}

TEST(StaircaseTextures, WallpaperLoads) {
    const fs::path file = fs::path(VRL_SHARED_SCENES_DIR) / "staircase" / "textures" / "Wallpaper.jpg";
    if (!fs::exists(file)) GTEST_SKIP() << "staircase scene not present: " << file;
    TextureDescription d;
    d.filename = file;
    const auto tex = Texture::load(d);
    EXPECT_EQ(tex->width(), 512);
    EXPECT_EQ(tex->height(), 512);
    for (int i = 0; i < 1000; ++i) {
        const Rgb c = tex->eval({float(i) * 0.0137f, float(i) * 0.0071f});
        EXPECT_TRUE(minComponent(c) >= 0.0f && maxComponent(c) <= 1.0f) << i;
    }
    EXPECT_GT(maxComponent(tex->average()), 0.0f);
    EXPECT_LE(maxComponent(tex->average()), 1.0f);
}

}  // namespace
}  // namespace vrl
