#include "render/image/image_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace vrl {
namespace {

// Grey pixels have luminance equal to their value (the weights sum to 1); the
// float weights leave a relative error of a few 1e-7.
constexpr double kTolerance = 1e-6;

Image greyRow(std::initializer_list<float> values) {
    Image image(int(values.size()), 1);
    int x = 0;
    for (float v : values) image.at(x++, 0) = Rgb(v);
    return image;
}

TEST(ImageMetricsTest, IdenticalImagesGiveZero) {
    Image image(5, 3);
    for (size_t i = 0; i < image.pixelCount(); ++i) image[i] = Rgb(0.1f * i, 2.0f, 0.0f);
    const ImageErrorMetrics m = compareImages(image, image);
    EXPECT_EQ(m.rmse, 0.0);
    EXPECT_EQ(m.relativeRmse, 0.0);
    EXPECT_EQ(m.smape, 0.0);
    EXPECT_EQ(m.pixels, 15u);
    EXPECT_EQ(m.nonFinitePixels, 0u);
}

TEST(ImageMetricsTest, HandComputedTwoPixels) {
    // R = {1, 0}, I = {3, 0.5}: differences 2 and 0.5.
    const ImageErrorMetrics m = compareImages(greyRow({1.0f, 0.0f}), greyRow({3.0f, 0.5f}));
    EXPECT_NEAR(m.rmse, std::sqrt((4.0 + 0.25) / 2.0), kTolerance);                // 1.457738
    EXPECT_NEAR(m.relativeRmse, std::sqrt((4.0 / 1.01 + 0.25 / 0.01) / 2.0), kTolerance);  // 3.805286
    EXPECT_NEAR(m.smape, (2.0 / 2.0) * (2.0 / 4.01 + 0.5 / 0.51), kTolerance);     // 1.479145
    EXPECT_EQ(m.pixels, 2u);
}

TEST(ImageMetricsTest, HandComputedUnderestimate) {
    // R = {4, 2, 1}, I = {2, 2, 0}: differences -2, 0, -1.
    const ImageErrorMetrics m = compareImages(greyRow({4.0f, 2.0f, 1.0f}), greyRow({2.0f, 2.0f, 0.0f}));
    EXPECT_NEAR(m.rmse, std::sqrt((4.0 + 0.0 + 1.0) / 3.0), kTolerance);                 // 1.290994
    EXPECT_NEAR(m.relativeRmse, std::sqrt((4.0 / 16.01 + 1.0 / 1.01) / 3.0), kTolerance);  // 0.642895
    EXPECT_NEAR(m.smape, (2.0 / 3.0) * (2.0 / 6.01 + 1.0 / 1.01), kTolerance);           // 0.881918
}

TEST(ImageMetricsTest, UsesLuminanceWeights) {
    Image reference(1, 1);
    Image test(1, 1);
    test[0] = Rgb(0.0f, 1.0f, 0.0f);  // luminance 0.715160
    const ImageErrorMetrics m = compareImages(reference, test);
    EXPECT_NEAR(m.rmse, 0.715160, kTolerance);
    EXPECT_NEAR(m.relativeRmse, 0.715160 / std::sqrt(0.01), kTolerance);
    EXPECT_NEAR(m.smape, 2.0 * 0.715160 / (0.715160 + 0.01), kTolerance);
}

TEST(ImageMetricsTest, SizeMismatchThrows) {
    try {
        compareImages(Image(640, 480), Image(320, 240));
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "image sizes differ: 640x480 vs 320x240");
    }
}

TEST(ImageMetricsTest, NonFiniteTestPixelsAreCountedAndExcluded) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    Image test = greyRow({2.0f, 0.0f, 0.0f, 1.0f});
    test.at(1, 0) = Rgb(nan, 0.0f, 0.0f);
    test.at(2, 0) = Rgb(0.0f, 0.0f, -inf);
    const ImageErrorMetrics m = compareImages(greyRow({1.0f, 1.0f, 1.0f, 1.0f}), test);
    EXPECT_EQ(m.pixels, 2u);
    EXPECT_EQ(m.nonFinitePixels, 2u);
    // Only pixels 0 (difference 1) and 3 (difference 0) count.
    EXPECT_NEAR(m.rmse, std::sqrt(1.0 / 2.0), kTolerance);
    EXPECT_NEAR(m.relativeRmse, std::sqrt((1.0 / 1.01) / 2.0), kTolerance);
    EXPECT_NEAR(m.smape, (2.0 / 2.0) * (1.0 / 3.01), kTolerance);
}

TEST(ImageMetricsTest, AllPixelsNonFiniteGivesNaN) {
    Image test(2, 1);
    test[0] = test[1] = Rgb(std::numeric_limits<float>::quiet_NaN());
    const ImageErrorMetrics m = compareImages(Image(2, 1), test);
    EXPECT_EQ(m.pixels, 0u);
    EXPECT_EQ(m.nonFinitePixels, 2u);
    EXPECT_TRUE(std::isnan(m.rmse));
    EXPECT_TRUE(std::isnan(m.relativeRmse));
    EXPECT_TRUE(std::isnan(m.smape));
}

TEST(ImageMetricsTest, NonFiniteReferenceThrows) {
    Image reference(3, 2);
    reference.at(2, 1) = Rgb(std::numeric_limits<float>::infinity());
    try {
        compareImages(reference, Image(3, 2));
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "reference image has a non-finite pixel at (2, 1)");
    }
}

}  // namespace
}  // namespace vrl
