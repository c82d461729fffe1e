// The parameters of the cluster bounds: which bound VRL cuts take for the phase
// factor in Henyey-Greenstein media (cluster_bound.h), which bound part (c)'s cut
// takes for a glossy receiver (surface_cluster_bound.h), and when a node's distance
// comes from its segments, its bounding sphere or its box.
#pragma once

#include <cstdint>

namespace vrl {

// How VRL cuts bound the phase factor in Henyey-Greenstein media (cluster_bound.h).
enum class HgBound : uint8_t {
    Cones,    // proven: HG over the cones of VRL directions and the polar angles about the camera ray
    Epsilon,  // heuristic: the isotropic bound x (1 + anisotropyEpsilon) (the paper's)
};

// How part (c)'s cut bounds a glossy receiver's f_s |cos| towards a node (surface_cluster_bound.h).
enum class GlossyBound : uint8_t {
    Cones,    // proven where the model has PreparedBsdf::coneBound (rough plastic and rough conductor,
              // Beckmann and GGX); the corners heuristic for the other glossy models
    Corners,  // heuristic: glossyMargin x the largest f|cos| towards the box's corners, centre and mirror point
};

struct ClusterBoundSettings {
    uint32_t exactDistanceBelow = 32;  // VRL nodes with at most this many VRLs: h_min from their segments
    // Larger VRL nodes: h_min from the box's bounding sphere (one distance) when that is
    // beyond this many radii, else from the box (a slab test and 12 edges); 0: always the box.
    float sphereDistanceBeyond = 0.0f;
    HgBound hgBound = HgBound::Cones;  // VRL cuts; VPL cuts always use the epsilon heuristic
    float anisotropyEpsilon = 1.0f;    // HgBound::Epsilon and VPL cuts: bound x (1 + epsilon)
    GlossyBound glossyBound = GlossyBound::Cones;  // part (c)'s glossy receivers
    float glossyMargin = 2.0f;         // GlossyBound::Corners: f|cos| towards the box's corners x this
};

}  // namespace vrl
