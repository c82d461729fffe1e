#include "service/common/limits_proto.h"

namespace vrl::rpc {

v1::ServiceLimits toProto(const ServiceLimits& l) {
    v1::ServiceLimits p;
    p.set_max_bundle_bytes(l.maxBundleBytes);
    p.set_max_bundle_files(l.maxBundleFiles);
    p.set_max_vrls(l.maxVrls);
    p.set_max_pixels(l.maxPixels);
    p.set_max_tile_size(l.maxTileSize);
    p.set_max_tiles(l.maxTiles);
    p.set_max_samples_per_pixel(l.maxSamplesPerPixel);
    return p;
}

ServiceLimits fromProto(const v1::ServiceLimits& p) {
    ServiceLimits l;
    l.maxBundleBytes = p.max_bundle_bytes();
    l.maxBundleFiles = p.max_bundle_files();
    l.maxVrls = p.max_vrls();
    l.maxPixels = p.max_pixels();
    l.maxTileSize = p.max_tile_size();
    l.maxTiles = p.max_tiles();
    l.maxSamplesPerPixel = p.max_samples_per_pixel();
    return l;
}

}  // namespace vrl::rpc
