// A job's lights blob (JobAssets.lights_sha256): the lights the coordinator
// traces once (prepareLights), as every worker receives them, so that a
// worker's TileShader shades with the very lights an embedded render would.
// The coordinator encodes, the workers decode; both call only these two.
//
// The blob is one of the serialisations of render/lightcuts/tree/light_tree_io.h:
//   vrl-stochastic with several VRL sets   "VRLTREES": every set's tree
//   a method with a light tree             "VRLTREE":  the tree (it holds the VRLs or VPLs)
//   vrl, vpl                               "VRLSET":   the VRLs or VPLs
// and where the job takes part (b)'s surface light from surface VPLs
// (usesSurfaceVpls), one "VRLLIGHT" blob of that primary blob (empty where no
// VRLs are kept: --transport single) and the "VRLSVPLS" blob of the VPLs. A job
// with no lights to ship (path, or light tracing that found none) has an empty
// blob and names none.
#pragma once

#include "render/renderer.h"

#include <cstdint>
#include <span>
#include <vector>

namespace vrl::rpc {

// The blob of `lights` as prepared for `settings`; empty when there is nothing to ship.
std::vector<uint8_t> encodeJobLights(const RenderLights& lights, const RenderSettings& settings);

// The lights of a non-empty blob of a job resolved to `settings`: bit for bit
// those encodeJobLights was given, as far as shading reads them (not the light
// tracing's timing, nor the light-path count of a set whose VRLs a tree holds). Throws
// std::runtime_error, with a message for the worker's log, for a blob the
// serialisers refuse (light_tree_io.h), one without the surface VPLs the
// settings need, or one whose number of VRL sets differs from settings.vrlSets.
RenderLights decodeJobLights(std::span<const uint8_t> blob, const RenderSettings& settings);

}  // namespace vrl::rpc
