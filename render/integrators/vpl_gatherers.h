// Part (d) from VPLs, points at the light paths' medium collisions (--method vpl,
// vpl-lightcuts; Vibert et al. 2019 §6): stratified distance samples along the
// camera segment, each gathering every VPL (VplEstimator) or a Lightcut through
// the VPL tree (VplLightcutsEstimator, the paper's baseline). Both draw their
// distance samples from vrlStream(streamKey, ~0u), so they differ by the cut alone.
#pragma once

#include "render/integrators/medium_gatherer.h"
#include "render/lightcuts/cuts/vpl_lightcuts_estimator.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/vrl/vpl_estimator.h"
#include "render/vrl/vrl.h"

#include <vector>

namespace vrl {

class PlainVplMediumGatherer final : public MediumGatherer {
public:
    PlainVplMediumGatherer(const Scene& scene, const std::vector<Vrl>& vpls, int distanceSamples)
        : estimator_(scene, vpls, distanceSamples) {}
    Rgb gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
               float otherLuminance) const override;

private:
    VplEstimator estimator_;
};

class VplCutMediumGatherer final : public MediumGatherer {
public:
    VplCutMediumGatherer(const Scene& scene, const LightTree& tree, const CutSettings& cut, int distanceSamples)
        : cut_(scene, tree, cut, distanceSamples) {}
    Rgb gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
               float otherLuminance) const override;

private:
    VplLightcutsEstimator cut_;
};

}  // namespace vrl
