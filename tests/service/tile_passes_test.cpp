// TilePasses (server/tile_passes.h): what each tile is leased next, and that
// the tile sums always hold whole passes: a pass a tile finished early is
// held apart until every tile has it, then added in pass order, so the image
// of the completed passes is exactly the fold sample_passes.h defines.
#include "server/tile_passes.h"

#include <gtest/gtest.h>

namespace vrl::server {
namespace {

using Range = TilePasses::Range;

// A 1x1 tile's sums of one layer holding `value`.
SampleSums pass(float value) {
    SampleSums sums = SampleSums::zeros(1, 1, {0});
    sums.layers[0][0] = Rgb(value);
    sums.boundedEstimates = 1;
    return sums;
}

const std::vector<TileRect> kTiles = {{0, 0, 1, 1}, {1, 0, 2, 1}};  // a 2x1 image, two 1x1 tiles

float pixel(const SampleSums& sums, int x) { return sums.layers[0].at(x, 0).x; }

TEST(TilePasses, AFixedJobLeasesEachTileOnceForAllItsPasses) {
    TilePasses passes(2, 3, false);
    EXPECT_EQ(passes.nextLease(0).first, 0);
    EXPECT_EQ(passes.nextLease(0).count, 3);
    EXPECT_EQ(passes.fit(0, {0, 1}), TilePasses::Fit::Unexpected);
    EXPECT_FALSE(passes.accept(0, {0, 3}, pass(5.0f)));
    EXPECT_EQ(passes.fit(0, {0, 3}), TilePasses::Fit::Duplicate);
    EXPECT_EQ(passes.nextLease(0).count, 0);
    EXPECT_TRUE(passes.tileDone(0));
    std::vector<uint8_t> covered;
    const SampleSums partial = passes.imageSums(kTiles, 2, 1, {0}, &covered);
    EXPECT_EQ(covered, (std::vector<uint8_t>{1, 0}));
    EXPECT_EQ(pixel(partial, 0), 5.0f);
    EXPECT_TRUE(passes.accept(1, {0, 3}, pass(7.0f)));
    EXPECT_EQ(passes.passesDone(), 3);
    EXPECT_EQ(pixel(passes.imageSums(kTiles, 2, 1, {0}), 1), 7.0f);
}

// Tile 0 runs two passes ahead; its sums join the image only when tile 1 has them.
TEST(TilePasses, AProgressiveJobFoldsAPassOnceEveryTileHasIt) {
    TilePasses passes(2, 4, true);
    EXPECT_EQ(passes.nextLease(0).first, 0);
    EXPECT_EQ(passes.nextLease(0).count, 1);
    EXPECT_FALSE(passes.accept(0, {0, 1}, pass(1.0f)));
    EXPECT_EQ(passes.nextLease(0).first, 1);
    EXPECT_EQ(passes.fit(0, {2, 1}), TilePasses::Fit::Unexpected) << "pass 2 before pass 1";
    EXPECT_EQ(passes.fit(0, {0, 1}), TilePasses::Fit::Duplicate);
    EXPECT_FALSE(passes.accept(0, {1, 1}, pass(2.0f)));
    EXPECT_EQ(passes.nextLease(0).count, 0) << "two passes ahead: it waits";
    EXPECT_EQ(passes.passesDone(), 0);
    EXPECT_EQ(passes.tilesInCurrentPass(), 1u);
    std::vector<uint8_t> covered;  // no whole pass: pass 0 of the tiles that have it
    SampleSums image = passes.imageSums(kTiles, 2, 1, {0}, &covered);
    EXPECT_EQ(covered, (std::vector<uint8_t>{1, 0}));
    EXPECT_EQ(pixel(image, 0), 1.0f);
    EXPECT_EQ(pixel(image, 1), 0.0f);

    EXPECT_TRUE(passes.accept(1, {0, 1}, pass(10.0f)));  // pass 0 complete everywhere
    EXPECT_EQ(passes.passesDone(), 1);
    EXPECT_EQ(passes.nextLease(0).first, 2) << "one pass ahead again: it may go on";
    image = passes.imageSums(kTiles, 2, 1, {0}, &covered);
    EXPECT_EQ(pixel(image, 0), 1.0f) << "pass 1 of tile 0 is held apart";
    EXPECT_EQ(pixel(image, 1), 10.0f);
    EXPECT_EQ(image.boundedEstimates, 2u);

    EXPECT_TRUE(passes.accept(1, {1, 1}, pass(20.0f)));
    EXPECT_EQ(passes.passesDone(), 2);
    image = passes.imageSums(kTiles, 2, 1, {0});
    EXPECT_EQ(pixel(image, 0), 3.0f);
    EXPECT_EQ(pixel(image, 1), 30.0f);
    for (const float value : {4.0f, 8.0f}) {
        EXPECT_FALSE(passes.accept(0, passes.nextLease(0), pass(value)));
        EXPECT_EQ(passes.accept(1, passes.nextLease(1), pass(value)), true);
    }
    EXPECT_EQ(passes.passesDone(), 4);
    EXPECT_TRUE(passes.tileDone(0));
    EXPECT_EQ(passes.nextLease(1).count, 0);
    EXPECT_EQ(pixel(passes.imageSums(kTiles, 2, 1, {0}), 0), 15.0f);  // ((1 + 2) + 4) + 8
    EXPECT_THROW(passes.accept(0, {4, 1}, pass(1.0f)), std::logic_error);
}

}  // namespace
}  // namespace vrl::server
