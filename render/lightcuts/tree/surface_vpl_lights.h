// SurfaceVplLights: the surface VPLs of a render (surface_vpl.h) in the order
// the cut's light tree indexes them, and that tree. Built by prepareSurfaceVpls
// (cuts/surface_vpl_lightcuts_estimator.h), shipped in the lights blob
// (light_tree_io.h).
#pragma once

#include "render/lightcuts/tree/light_tree.h"
#include "render/vrl/surface_vpl.h"

#include <cstddef>
#include <vector>

namespace vrl {

// The surface VPLs of a render in the order the cut's tree indexes them, and that tree.
struct SurfaceVplLights {
    std::vector<SurfaceVpl> vpls;
    LightTree tree;  // over proxies (above); empty for plain shading or without VPLs
    size_t memoryBytes() const { return vpls.capacity() * sizeof(SurfaceVpl) + tree.memoryBytes(); }
};

}  // namespace vrl
