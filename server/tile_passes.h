// TilePasses: a job's sample sums per tile over its sample passes
// (render/sample_passes.h, render/sample_sums.h), and which passes each tile
// is leased next.
//
// A job without a time limit leases each tile once for all its passes
// [0, passesTotal): the result is the tile's whole sum. A job with a time
// limit (progressive) leases (tile, pass) one pass at a time, in pass order
// per tile; a tile may run at most kPassesAhead passes ahead of the passes
// complete over the whole image, and its results for passes not yet complete
// everywhere are held apart ("ahead") until the last tile has that pass: only
// then are they added to the tile sums, in pass order, so the sums always hold
// exactly passesDone() passes everywhere and the image of the completed
// passes equals the fixed render of samplesAfter(passesDone) samples bit for bit.
//
// Plain data under the Coordinator's lock (not thread-safe by itself).
#pragma once

#include "render/renderer.h"
#include "render/sample_sums.h"

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace vrl::server {

class TilePasses {
public:
    static constexpr int kPassesAhead = 2;

    // Passes [first, first + count) of a tile; count 0: none.
    struct Range {
        int first = 0, count = 0;
    };
    // How a result's passes fit its tile.
    enum class Fit { Expected, Duplicate, Unexpected };

    TilePasses() = default;
    TilePasses(size_t tiles, int passesTotal, bool progressive);

    // What tile `t` is leased next: all passes (fixed), its next pass while it
    // is fewer than kPassesAhead ahead (progressive); {0, 0} when it is done or
    // must wait for the other tiles.
    Range nextLease(uint32_t t) const;
    Fit fit(uint32_t t, Range passes) const;
    // The one pass (or all passes) a result of tile `t` brings, with `fit` Expected.
    // Returns true when it completed a pass over the whole image.
    bool accept(uint32_t t, Range passes, SampleSums sums);

    bool tileDone(uint32_t t) const;  // every pass of the tile accepted
    int passesTotal() const { return passesTotal_; }
    int passesDone() const { return passesDone_; }  // complete over the whole image
    bool progressive() const { return progressive_; }
    // Tiles that hold the pass being rendered (fixed: tiles done).
    uint32_t tilesInCurrentPass() const;
    // The per-layer flags of the first result (empty before any).
    const std::vector<uint8_t>& perPixel() const { return perPixel_; }

    // The image's sums of its completed passes; when none completed, those of
    // the tiles that finished pass 0 (the others zero), and `covered` (if given)
    // marks those tiles. `perPixel` sizes an image no tile has reached yet.
    SampleSums imageSums(const std::vector<TileRect>& tiles, int width, int height,
                         const std::vector<uint8_t>& perPixel, std::vector<uint8_t>* covered = nullptr) const;
    void clear();  // frees the sums (the job ended)

private:
    int passesTotal_ = 0, passesDone_ = 0;
    bool progressive_ = false;
    std::vector<SampleSums> sums_;                // per tile: passes [0, passesDone_) (fixed: all, once done)
    std::vector<uint8_t> hasSums_;                // per tile: sums_ is set
    std::vector<std::deque<SampleSums>> ahead_;  // progressive: per tile, its passes passesDone_, ... not yet folded
    uint32_t tilesWithPass_ = 0;                  // progressive: tiles with a non-empty ahead_
    std::vector<uint8_t> perPixel_;
};

}  // namespace vrl::server
