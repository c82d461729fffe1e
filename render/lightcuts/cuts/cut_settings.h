// Settings and per-pixel statistics shared by every Lightcuts walk (VRL and VPL
// cuts, cut_walk.h): the relative error threshold, the cut-size safety valve,
// the parameters of the cluster bounds (cluster_bound_settings.h), and the
// counters of the paper's Table 1.
#pragma once

#include "render/lightcuts/bounds/cluster_bound_settings.h"

#include <cstdint>

namespace vrl {

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
