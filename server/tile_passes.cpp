#include "server/tile_passes.h"

#include <stdexcept>

namespace vrl::server {

TilePasses::TilePasses(size_t tiles, int passesTotal, bool progressive)
    : passesTotal_(passesTotal), progressive_(progressive), sums_(tiles), hasSums_(tiles, 0), ahead_(tiles) {}

TilePasses::Range TilePasses::nextLease(uint32_t t) const {
    if (tileDone(t)) return {};
    if (!progressive_) return {0, passesTotal_};
    const int ahead = int(ahead_[t].size());
    const int next = passesDone_ + ahead;
    if (ahead >= kPassesAhead || next >= passesTotal_) return {};
    return {next, 1};
}

TilePasses::Fit TilePasses::fit(uint32_t t, Range passes) const {
    if (!progressive_) {
        if (passes.first != 0 || passes.count != passesTotal_) return Fit::Unexpected;
        return hasSums_[t] ? Fit::Duplicate : Fit::Expected;
    }
    if (passes.count != 1) return Fit::Unexpected;
    const int next = passesDone_ + int(ahead_[t].size());
    if (passes.first < next) return Fit::Duplicate;
    return passes.first == next && next < passesTotal_ ? Fit::Expected : Fit::Unexpected;
}

bool TilePasses::accept(uint32_t t, Range passes, SampleSums sums) {
    if (fit(t, passes) != Fit::Expected) throw std::logic_error("TilePasses::accept: a result that does not fit");
    if (perPixel_.empty()) perPixel_ = sums.perPixel;
    if (!progressive_) {
        sums_[t] = std::move(sums);
        hasSums_[t] = 1;
        bool all = true;
        for (const uint8_t has : hasSums_) all = all && has;
        if (all) passesDone_ = passesTotal_;
        return all;
    }
    if (ahead_[t].empty()) ++tilesWithPass_;
    ahead_[t].push_back(std::move(sums));
    bool completed = false;
    while (tilesWithPass_ == ahead_.size() && !ahead_.empty()) {  // every tile has pass passesDone_: fold it
        tilesWithPass_ = 0;
        for (size_t i = 0; i < ahead_.size(); ++i) {
            if (!hasSums_[i]) {
                sums_[i] = std::move(ahead_[i].front());
                hasSums_[i] = 1;
            } else {
                addPass(sums_[i], ahead_[i].front());
            }
            ahead_[i].pop_front();
            tilesWithPass_ += !ahead_[i].empty();
        }
        ++passesDone_;
        completed = true;
    }
    return completed;
}

bool TilePasses::tileDone(uint32_t t) const {
    if (!progressive_) return hasSums_[t] != 0;
    return passesDone_ + int(ahead_[t].size()) >= passesTotal_;
}

uint32_t TilePasses::tilesInCurrentPass() const {
    if (!progressive_) {
        uint32_t done = 0;
        for (const uint8_t has : hasSums_) done += has;
        return done;
    }
    return passesDone_ >= passesTotal_ ? uint32_t(sums_.size()) : tilesWithPass_;
}

SampleSums TilePasses::imageSums(const std::vector<TileRect>& tiles, int width, int height,
                                 const std::vector<uint8_t>& perPixel, std::vector<uint8_t>* covered) const {
    if (tiles.size() != sums_.size()) throw std::invalid_argument("TilePasses::imageSums: tile count mismatch");
    SampleSums image = SampleSums::zeros(width, height, perPixel_.empty() ? perPixel : perPixel_);
    if (covered) covered->assign(tiles.size(), 0);
    for (size_t t = 0; t < tiles.size(); ++t) {
        // Whole passes if any; else (progressive) pass 0 of the tiles that have it.
        const SampleSums* tile = hasSums_[t] ? &sums_[t]
                                 : (progressive_ && passesDone_ == 0 && !ahead_[t].empty()) ? &ahead_[t].front()
                                                                                           : nullptr;
        if (!tile) continue;
        copyRows(image, *tile, tiles[t].x0, tiles[t].y0, tiles[t].height());
        image.boundExceeded += tile->boundExceeded;
        image.boundedEstimates += tile->boundedEstimates;
        if (covered) (*covered)[t] = 1;
    }
    return image;
}

void TilePasses::clear() {
    const size_t tiles = sums_.size();
    std::vector<SampleSums>(tiles).swap(sums_);
    std::vector<std::deque<SampleSums>>(tiles).swap(ahead_);
}

}  // namespace vrl::server
