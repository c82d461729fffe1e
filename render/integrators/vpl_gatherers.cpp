#include "render/integrators/vpl_gatherers.h"

#include "render/vrl/vrl_estimator.h"

namespace vrl {

Rgb PlainVplMediumGatherer::gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics&, float) const {
    Rng rng = vrlStream(streamKey, ~0u);
    return estimator_.estimate(segment, rng);
}

Rgb VplCutMediumGatherer::gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                                 float) const {
    Rng rng = vrlStream(streamKey, ~0u);
    return cut_.estimate(segment, rng, statistics);
}

}  // namespace vrl
