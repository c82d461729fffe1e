// Binary serialisation of a LightTree (its VRLs and nodes), so a tree built once
// can be cached on disk or shipped to another worker and used bit-for-bit.
//
// Layout, every field little-endian, written field by field (no struct memory,
// so neither padding nor ABI leaks in); floats as their IEEE-754 bit patterns,
// so -0 and NaN payloads survive:
//   magic    8 bytes  "VRLTREE\0"
//   version  u32      kLightTreeFormatVersion
//   vrls     u32      number of VRLs V
//   nodes    u32      number of nodes N
//   root     i32      root node index, -1 for an empty tree
//   V x VRL  44 bytes origin xyz, direction xyz, length, flux rgb (f32), medium (i32)
//   N x node 72 bytes box min xyz, box max xyz, fluxLength rgb, clusterFlux rgb,
//                     maxLength (f32), representative, vrlCount (u32),
//                     left, right, medium (i32)
//   crc      u32      CRC-32 (zlib) of every byte before it
#pragma once

#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/tree/surface_vpl_lights.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace vrl {

inline constexpr uint32_t kLightTreeFormatVersion = 1;

// Serialises `tree` into a self-contained blob (layout above). Throws
// std::invalid_argument if it has more than 2^32 - 1 VRLs or nodes.
std::vector<uint8_t> serializeLightTree(const LightTree& tree);

// Parses a blob written by serializeLightTree; the bit-exact inverse.
// Throws std::runtime_error, with a message a user can act on, for: a wrong
// magic ("not a VRL light tree"), another format version (both named), a blob
// shorter or longer than its header's counts require (bytes expected and
// found), a checksum mismatch, and a structurally invalid tree (the reason
// LightTree::fromParts gives). Checks are made in that order. Never reads out
// of bounds; counts are checked against the blob size before anything is
// allocated from them.
LightTree deserializeLightTree(const uint8_t* data, size_t size);
inline LightTree deserializeLightTree(const std::vector<uint8_t>& blob) {
    return deserializeLightTree(blob.data(), blob.size());
}

// The plain `vrl` method ships its VRLs without a tree, in the same style:
//   magic "VRLSET\0\0", version u32 (kLightTreeFormatVersion), count u32,
//   light paths u32 low + u32 high, count x VRL (44 bytes as above), crc u32.
std::vector<uint8_t> serializeVrlSet(const VrlSet& set);
// The inverse; throws std::runtime_error (wrong magic or version, wrong size,
// checksum mismatch) like deserializeLightTree.
VrlSet deserializeVrlSet(const uint8_t* data, size_t size);

// Several independent trees in one blob (vrl-stochastic with --vrl-sets P, renderer.h):
//   magic "VRLTREES", version u32 (kLightTreeFormatVersion), count u32 (1 ... kMaxLightTreesInBlob),
//   count x size u64, then the count tree blobs (serializeLightTree) back to back, crc u32
//   over every byte before it.
inline constexpr uint32_t kMaxLightTreesInBlob = 1024;
std::vector<uint8_t> serializeLightTrees(const std::vector<const LightTree*>& trees);
// The inverse; throws std::runtime_error like deserializeLightTree (wrong magic or version,
// a count out of range, sizes that do not add up to the blob, a checksum mismatch), and
// with the tree's index for a tree that deserializeLightTree refuses.
std::vector<LightTree> deserializeLightTrees(const uint8_t* data, size_t size);

// Part (b)'s surface VPLs and their cut's tree (surface_vpl_lightcuts_estimator.h), in the same style:
//   magic    8 bytes  "VRLSVPLS"
//   version  u32      kLightTreeFormatVersion
//   count    u32      number of VPLs K
//   K x VPL  84 bytes position, geometricNormal, shadingNormal xyz, uv (f32), shape,
//                     triangle (u32), scale, direction xyz, flux rgb (f32), medium (i32)
//   hasTree  u32      0: no tree (plain shading, or no VPLs); 1: a tree follows
//   [size    u64      as u32 low + u32 high, then the tree's serializeLightTree blob]
//   crc      u32      CRC-32 (zlib) of every byte before it
std::vector<uint8_t> serializeSurfaceVpls(const SurfaceVplLights& lights);
// The bit-exact inverse; throws std::runtime_error like deserializeLightTree (wrong magic
// or version, a size that does not match the counts, a tree flag other than 0 or 1, a
// checksum mismatch), for a tree that deserializeLightTree refuses (its reason, prefixed),
// and for a tree that is empty or does not hold exactly K lights (one proxy per VPL).
SurfaceVplLights deserializeSurfaceVpls(const uint8_t* data, size_t size);

// The one lights blob of a job (JobAssets.lights_sha256) when it has surface VPLs:
//   magic "VRLLIGHT", version u32 (kLightTreeFormatVersion), primary size u64, surface
//   size u64 (each as u32 low + u32 high), the primary blob, the surface VPL blob, crc u32.
// The primary blob is what a job without surface VPLs ships alone, unchanged: a tree, a
// "VRLTREES" blob or a VRL set; empty where no VRLs are kept (part (b) alone). Jobs
// without surface VPLs ship their primary blob bare, so their blobs are as before.
std::vector<uint8_t> serializeJobLights(std::span<const uint8_t> primary, std::span<const uint8_t> surfaceVpls);
struct JobLightsParts {
    std::span<const uint8_t> primary;      // empty: none
    std::span<const uint8_t> surfaceVpls;  // empty: none
};
// Splits a "VRLLIGHT" blob into views of its two parts (into `data`, which must
// outlive them); checks its magic, version, sizes and checksum, not the parts.
// Throws std::runtime_error like deserializeLightTree.
JobLightsParts parseJobLights(const uint8_t* data, size_t size);

}  // namespace vrl
