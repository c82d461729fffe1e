// Settings and per-pixel statistics shared by every Lightcuts walk (VRL and VPL
// cuts, cut_walk.h): the relative error threshold, the cut-size safety valve,
// the parameters of the cluster bounds, and the counters of the paper's Table 1.
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

// VPL Lightcuts and plain VPLs: stratified distance samples per camera segment, each
// one cut (or gather) at a point of the segment. The one default for the renderer
// (RenderSettings), the integrator and the VPL estimators.
inline constexpr int kDefaultVplDistanceSamples = 32;

struct CutSettings {
    float errorThreshold = 0.02f;
    uint32_t maxCutSize = 4096;
    uint32_t stochasticCutSize = 32;  // vrl-stochastic: nodes per cut (K), one VRL drawn under each
    ClusterBoundSettings bound;
};

// Per-pixel counters (the paper's Table 1).
struct CutStatistics {
    uint32_t evaluated = 0;    // #Eval: nodes and leaves estimated in the cut (as in the paper; a child that
                               // shares its refined parent's representative inherits its estimate and costs
                               // no estimator call, cut_walk.h)
    uint32_t intersected = 0;  // #Inter: nodes whose box the camera line crossed
    uint32_t cutSize = 0;      // nodes in the final cut
    uint32_t boundExceeded = 0;  // inner-node estimates above the bound they last had (heuristic bounds:
                                 // VPL cuts' HG, glossy receivers, deferred cheap bounds; cut_walk.h)
    uint32_t boundedEstimates = 0;  // inner-node estimates checked against their bound
    uint32_t importanceEvaluations = 0;  // stochastic cuts: node importances computed (cut and descents)

    CutStatistics& operator+=(const CutStatistics& o) {
        evaluated += o.evaluated, intersected += o.intersected, cutSize += o.cutSize;
        boundExceeded += o.boundExceeded, boundedEstimates += o.boundedEstimates;
        importanceEvaluations += o.importanceEvaluations;
        return *this;
    }
};

}  // namespace vrl
