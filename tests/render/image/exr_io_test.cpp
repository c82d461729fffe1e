#include "render/image/exr_io.h"
#include "render/image/partial_image.h"
#include "tests/support/temp_dir.h"

#include <gtest/gtest.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>

#include <Imath/half.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

namespace vrl {
namespace {

namespace fs = std::filesystem;

// Each test works in its own directory, removed afterwards.
class ExrIoTest : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
        dir_ = test::freshDirectory("vrl_exr_io_test_" + test);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path dir_;
};

// Random values over many magnitudes and both signs, plus a few special values.
Image randomImage(int width, int height, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> mantissa(-1.0f, 1.0f);
    std::uniform_int_distribution<int> exponent(-40, 38);
    Image image(width, height);
    for (size_t i = 0; i < image.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c) image[i][c] = mantissa(rng) * std::pow(10.0f, float(exponent(rng)));
    const float specials[] = {-0.0f, std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                              std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::infinity()};
    for (size_t i = 0; i < std::size(specials) && i < image.pixelCount(); ++i) image[i].y = specials[i];
    return image;
}

void expectBitExact(const Image& expected, const Image& actual, const std::string& what) {
    ASSERT_EQ(expected.width(), actual.width()) << what;
    ASSERT_EQ(expected.height(), actual.height()) << what;
    for (size_t i = 0; i < expected.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c)
            ASSERT_EQ(std::bit_cast<uint32_t>(expected[i][c]), std::bit_cast<uint32_t>(actual[i][c]))
                << what << ": pixel " << i << " component " << c;
}

// Expects `action` to throw std::runtime_error whose message contains `path`.
void expectRuntimeErrorNaming(const std::function<void()>& action, const fs::path& path) {
    try {
        action();
        FAIL() << "no exception for " << path;
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
}

// Writes a half-float file with the given channels over `dataWindow`, as other tools do;
// channel k of pixel i (row-major from the data window's corner) holds (k + 1) * i.
void writeForeignExr(const fs::path& path, const Imath::Box2i& dataWindow, const std::vector<std::string>& names) {
    Imf::Header header(Imath::Box2i({0, 0}, {9, 9}), dataWindow);
    const int width = dataWindow.max.x - dataWindow.min.x + 1;
    const int height = dataWindow.max.y - dataWindow.min.y + 1;
    std::vector<std::vector<half>> planes;
    Imf::FrameBuffer frameBuffer;
    for (size_t k = 0; k < names.size(); ++k) {
        planes.emplace_back(size_t(width) * height);
        for (size_t i = 0; i < planes.back().size(); ++i) planes.back()[i] = half(float((k + 1) * i));
    }
    for (size_t k = 0; k < names.size(); ++k) {
        header.channels().insert(names[k], Imf::Channel(Imf::HALF));
        frameBuffer.insert(names[k], Imf::Slice::Make(Imf::HALF, planes[k].data(), dataWindow));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frameBuffer);
    file.writePixels(height);
}

TEST_F(ExrIoTest, RoundTripIsBitExact) {
    ImageSet written;
    written.image = randomImage(7, 3, 1);
    written.layers = {{"transport.single", randomImage(7, 3, 2)}, {"direct", randomImage(7, 3, 3)}};
    written.metadata = {{"vrl.scene", "scenes/smoke.xml"}, {"vrl.method", "vrl-cuts"}, {"vrl.empty", ""}};
    const fs::path path = dir_ / "round_trip.exr";
    writeExr(path, written);
    const ImageSet read = readExr(path);

    expectBitExact(written.image, read.image, "image");
    ASSERT_EQ(read.layers.size(), 2u);
    // Layers come back ordered by name.
    EXPECT_EQ(read.layers[0].first, "direct");
    expectBitExact(written.layers[1].second, read.layers[0].second, "layer direct");
    EXPECT_EQ(read.layers[1].first, "transport.single");
    expectBitExact(written.layers[0].second, read.layers[1].second, "layer transport.single");
    EXPECT_EQ(read.metadata, written.metadata);
}

// Half precision (cached references): values come back to half's precision
// (relative 2^-11 for normal numbers; the random values here are in [0, 8)), the
// file is smaller than the float one, and a value beyond 65504 is refused.
TEST_F(ExrIoTest, HalfPrecisionRoundTripsToHalfAccuracy) {
    const auto moderate = [](uint32_t seed) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<float> value(0.0f, 8.0f);
        Image image(17, 9);
        for (size_t i = 0; i < image.pixelCount(); ++i) image[i] = Rgb(value(rng), value(rng), value(rng));
        return image;
    };
    ImageSet written;
    written.image = moderate(4);
    written.layers = {{"half1", moderate(5)}};
    const fs::path halfPath = dir_ / "half.exr", floatPath = dir_ / "float.exr";
    writeExr(halfPath, written, ExrPixels::Half);
    writeExr(floatPath, written);
    const ImageSet read = readExr(halfPath);
    ASSERT_EQ(read.layers.size(), 1u);
    for (size_t i = 0; i < written.image.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c) {
            const float a = written.image[i][c], b = read.image[i][c];
            EXPECT_NEAR(b, a, std::abs(a) * 0x1p-11f + 6e-8f) << i;
            EXPECT_NEAR(read.layers[0].second[i][c], written.layers[0].second[i][c],
                        std::abs(written.layers[0].second[i][c]) * 0x1p-11f + 6e-8f);
        }
    EXPECT_LT(fs::file_size(halfPath), fs::file_size(floatPath));
    ImageSet bright = written;
    bright.layers[0].second[3] = Rgb(70000.0f, 1.0f, 1.0f);
    try {
        writeExr(dir_ / "bright.exr", bright, ExrPixels::Half);
        FAIL() << "no exception for a value beyond half's range";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("half1"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir_ / "bright.exr"));
}

// Counter layers are one channel ("eval.Y"), read back grey and still marked single-channel.
TEST_F(ExrIoTest, SingleChannelLayersRoundTripAsOneChannel) {
    ImageSet written;
    written.image = randomImage(5, 4, 1);
    Image counts(5, 4);
    for (size_t i = 0; i < counts.pixelCount(); ++i) counts[i] = Rgb(float(i * 7));
    written.layers = {{"eval", counts}, {"surface", randomImage(5, 4, 2)}};
    written.singleChannelLayers = {"eval"};
    const fs::path path = dir_ / "single.exr";
    writeExr(path, written);
    {
        Imf::InputFile file(path.c_str());
        const Imf::ChannelList& channels = file.header().channels();
        EXPECT_TRUE(channels.findChannel("eval.Y"));
        EXPECT_FALSE(channels.findChannel("eval.R"));
        EXPECT_TRUE(channels.findChannel("surface.R"));
    }
    const ImageSet read = readExr(path);
    ASSERT_EQ(read.layers.size(), 2u);
    EXPECT_EQ(read.layers[0].first, "eval");
    expectBitExact(counts, read.layers[0].second, "eval");
    EXPECT_EQ(read.singleChannelLayers, std::set<std::string>{"eval"});

    written.singleChannelLayers = {"nosuch"};
    EXPECT_THROW(writeExr(dir_ / "bad.exr", written), std::invalid_argument);
}

// A partial image carries its coverage (one channel) and vrl.partial / vrl.tilesTotal.
TEST_F(ExrIoTest, PartialImageCarriesCoverageAndTileCounts) {
    ImageSet images;
    images.image = randomImage(4, 2, 3);
    std::vector<uint8_t> covered = {1, 1, 0, 0, 1, 1, 0, 0};
    markPartial(images, covered, 1, 2);
    const fs::path path = dir_ / "partial.exr";
    writeExr(path, images);
    const ImageSet read = readExr(path);
    ASSERT_EQ(read.layers.size(), 1u);
    EXPECT_EQ(read.layers[0].first, kCoverageLayer);
    for (size_t i = 0; i < covered.size(); ++i) EXPECT_EQ(read.layers[0].second[i].x, covered[i] ? 1.0f : 0.0f);
    EXPECT_EQ(std::get<int32_t>(read.metadata.at(kPartialKey)), 1);
    EXPECT_EQ(std::get<int32_t>(read.metadata.at(kTilesTotalKey)), 2);
    EXPECT_THROW(markPartial(images, covered, 1, 2), std::invalid_argument);  // already partial
    ImageSet other;
    other.image = randomImage(4, 2, 3);
    EXPECT_THROW(markPartial(other, {1, 0}, 1, 2), std::invalid_argument);   // wrong coverage size
    EXPECT_THROW(markPartial(other, covered, 3, 2), std::invalid_argument);  // more tiles done than exist
}

// Numbers stay numbers: int, float, double and M44f attributes come back with their
// types and bits (render/image/metadata.h); OpenEXR's own numeric attributes
// (e.g. pixelAspectRatio) are not reported as metadata.
TEST_F(ExrIoTest, TypedMetadataRoundTrips) {
    ImageSet written;
    written.image = randomImage(4, 2, 5);
    Imath::M44f matrix;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) matrix[r][c] = 0.25f * float(r) - float(c) + 1e-3f;
    written.metadata = {{"vrl.spp", int32_t(-7)},      {"vrl.error", 0.02f},           {"vrl.time.render", 1.0 / 3.0},
                        {"vrl.method", std::string("vrl")}, {"worldToCamera", matrix}, {"vrl.vrls", 4294967296.0}};
    const fs::path path = dir_ / "typed.exr";
    writeExr(path, written);
    const ImageSet read = readExr(path);
    EXPECT_EQ(read.metadata, written.metadata);
    EXPECT_EQ(std::get<int32_t>(read.metadata.at("vrl.spp")), -7);
    EXPECT_EQ(std::get<float>(read.metadata.at("vrl.error")), 0.02f);
    EXPECT_EQ(std::get<double>(read.metadata.at("vrl.time.render")), 1.0 / 3.0);
    EXPECT_EQ(metadataNumber(read.metadata.at("vrl.vrls")), 4294967296.0);
    EXPECT_EQ(metadataText(read.metadata.at("vrl.spp")), "-7");
    EXPECT_EQ(read.metadata.count("pixelAspectRatio"), 0u);
    EXPECT_THROW((void)metadataNumber(read.metadata.at("vrl.method")), std::invalid_argument);
}

TEST_F(ExrIoTest, RoundTripOfSinglePixelWithoutLayers) {
    ImageSet written;
    written.image = Image(1, 1);
    written.image[0] = Rgb(-1.5f, 0.0f, 1e30f);
    const fs::path path = dir_ / "pixel.exr";
    writeExr(path, written);
    const ImageSet read = readExr(path);
    expectBitExact(written.image, read.image, "image");
    EXPECT_TRUE(read.layers.empty());
    EXPECT_TRUE(read.metadata.empty());
}

TEST_F(ExrIoTest, WriteReplacesExistingFileAndLeavesNoTemporary) {
    const fs::path path = dir_ / "replace.exr";
    ImageSet first;
    first.image = randomImage(4, 4, 4);
    writeExr(path, first);
    ImageSet second;
    second.image = randomImage(5, 2, 5);
    writeExr(path, second);
    expectBitExact(second.image, readExr(path).image, "image");
    EXPECT_EQ(std::vector<fs::path>{path}, std::vector<fs::path>(fs::directory_iterator(dir_), {}));
}

TEST_F(ExrIoTest, FailedWriteKeepsExistingFile) {
    const fs::path path = dir_ / "keep.exr";
    ImageSet good;
    good.image = randomImage(3, 3, 6);
    writeExr(path, good);
    ImageSet bad = good;
    bad.metadata["channels"] = "clashes with the channel list attribute";
    expectRuntimeErrorNaming([&] { writeExr(path, bad); }, path);
    expectBitExact(good.image, readExr(path).image, "image");
    EXPECT_FALSE(fs::exists(dir_ / "keep.exr.tmp"));
}

TEST_F(ExrIoTest, WriteRejectsInvalidImageSets) {
    ImageSet valid;
    valid.image = Image(4, 4);
    valid.layers = {{"direct", Image(4, 4)}};
    std::vector<std::pair<std::string, ImageSet>> cases(5, {"", valid});
    cases[0].first = "empty image";
    cases[0].second.image = Image();
    cases[1].first = "layer of other size";
    cases[1].second.layers[0].second = Image(4, 3);
    cases[2].first = "empty layer name";
    cases[2].second.layers[0].first = "";
    cases[3].first = "duplicate layer";
    cases[3].second.layers.push_back(valid.layers[0]);
    cases[4].first = "part type key";
    cases[4].second.metadata["type"] = "tiledimage";
    for (const auto& [what, images] : cases) {
        EXPECT_THROW(writeExr(dir_ / "bad.exr", images), std::invalid_argument) << what;
    }
    EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(ExrIoTest, WritingIntoMissingDirectoryThrows) {
    ImageSet images;
    images.image = Image(2, 2);
    const fs::path path = dir_ / "no_such_dir" / "out.exr";
    expectRuntimeErrorNaming([&] { writeExr(path, images); }, path);
    EXPECT_FALSE(fs::exists(dir_ / "no_such_dir"));
}

TEST_F(ExrIoTest, ReadingMissingFileThrows) {
    const fs::path path = dir_ / "missing.exr";
    expectRuntimeErrorNaming([&] { readExr(path); }, path);
}

TEST_F(ExrIoTest, ReadingTruncatedFileThrows) {
    const fs::path path = dir_ / "truncated.exr";
    ImageSet images;
    images.image = randomImage(64, 64, 7);
    writeExr(path, images);
    fs::resize_file(path, fs::file_size(path) / 2);
    expectRuntimeErrorNaming([&] { readExr(path); }, path);
}

TEST_F(ExrIoTest, ReadingNonExrFileThrows) {
    const fs::path path = dir_ / "text.exr";
    std::ofstream(path) << "This is not an OpenEXR file, only some text pretending to be one.\n";
    expectRuntimeErrorNaming([&] { readExr(path); }, path);
}

TEST_F(ExrIoTest, ReadsOffsetDataWindowAndHalfChannels) {
    const fs::path path = dir_ / "offset.exr";
    const Imath::Box2i dataWindow({-2, 5}, {2, 7});  // 5x3, partly outside the display window
    writeForeignExr(path, dataWindow, {"B", "G", "R", "spec.B", "spec.G", "spec.R", "depth.Z"});
    const ImageSet read = readExr(path);
    ASSERT_EQ(read.image.width(), 5);
    ASSERT_EQ(read.image.height(), 3);
    for (size_t i = 0; i < 15; ++i) {
        EXPECT_EQ(read.image[i], Rgb(3.0f * i, 2.0f * i, 1.0f * i)) << i;
    }
    ASSERT_EQ(read.layers.size(), 1u);  // depth.Z is not an RGB triple
    EXPECT_EQ(read.layers[0].first, "spec");
    EXPECT_EQ(read.layers[0].second.at(4, 2), Rgb(6.0f * 14, 5.0f * 14, 4.0f * 14));
}

TEST_F(ExrIoTest, ReadsLuminanceChannelAsGrey) {
    const fs::path path = dir_ / "grey.exr";
    writeForeignExr(path, Imath::Box2i({0, 0}, {2, 1}), {"Y"});
    const ImageSet read = readExr(path);
    ASSERT_EQ(read.image.pixelCount(), 6u);
    for (size_t i = 0; i < 6; ++i) EXPECT_EQ(read.image[i], Rgb(float(i))) << i;
}

TEST_F(ExrIoTest, ReadingFileWithoutBlueNamesTheMissingChannel) {
    const fs::path path = dir_ / "red_green.exr";
    writeForeignExr(path, Imath::Box2i({0, 0}, {1, 1}), {"R", "G"});
    try {
        readExr(path);
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(path.string()), std::string::npos) << message;
        EXPECT_NE(message.find("missing channel(s) B"), std::string::npos) << message;
    }
}

}  // namespace
}  // namespace vrl
