// Limits the coordinator enforces on what clients send (documented in the
// README; each is a flag of vrl-coordinator). Workers apply the same bundle
// limits to what they download.
#pragma once

#include <cstdint>

namespace vrl::rpc {

struct ServiceLimits {
    uint64_t maxBundleBytes = 1ULL << 30;  // a scene bundle (all files) at most 1 GiB
    uint32_t maxBundleFiles = 10000;       // files per bundle
    uint64_t maxVrls = 50'000'000;         // VRLs (or light paths) a job may ask for (~2.2 GB of VRLs)
    uint64_t maxPixels = 64ULL << 20;      // width x height (also each side <= 16384)
    uint32_t maxTileSize = 256;            // tile side
    uint64_t maxTiles = 1 << 20;           // tiles per image (a bound on per-tile bookkeeping)
    int maxSamplesPerPixel = 1 << 20;
};

}  // namespace vrl::rpc
