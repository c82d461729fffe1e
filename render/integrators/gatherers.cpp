#include "render/integrators/gatherers.h"

#include "render/integrators/stochastic_vrl_gatherers.h"
#include "render/integrators/vpl_gatherers.h"
#include "render/integrators/vrl_gatherers.h"
#include "render/lightcuts/cuts/vrl_importance.h"

#include <stdexcept>

namespace vrl {

Gatherers makeGatherers(const Scene& scene, const TransportSelection& transports, const PartEstimators& kinds,
                        const GathererInputs& inputs) {
    static const std::vector<Vrl> kNone;
    const LightTree* tree = inputs.tree;
    const std::vector<Vrl>& lights = tree ? tree->vrls() : inputs.lights ? *inputs.lights : kNone;
    // What (c) and (d) share: one bound data of the VRL cuts, one stochastic cut.
    std::shared_ptr<const VrlCutBoundData> vrlCutBounds;
    const auto bounds = [&] {
        if (!vrlCutBounds) vrlCutBounds = std::make_shared<const VrlCutBoundData>(scene, *tree);
        return vrlCutBounds;
    };
    std::shared_ptr<const StochasticVrlCuts> stochasticCuts;
    const auto stochastic = [&] {
        if (!stochasticCuts)
            stochasticCuts = std::make_shared<const StochasticVrlCuts>(scene, *tree, inputs.vrlSamples, inputs.cut);
        return stochasticCuts;
    };

    Gatherers out;
    if (transports.has(TransportPart::Multiple)) {
        switch (tree || !isCut(kinds.multiple) ? kinds.multiple
                : kinds.multiple == MediumGathererKind::VplCut ? MediumGathererKind::PlainVpls
                                                                : MediumGathererKind::PlainVrls) {
            case MediumGathererKind::None:
                throw std::invalid_argument("part (d) needs virtual lights (MediumGathererKind::None)");
            case MediumGathererKind::PlainVrls:
                out.multiple = std::make_unique<PlainVrlMediumGatherer>(scene, lights, inputs.vrlSamples);
                break;
            case MediumGathererKind::VrlCut:
                out.multiple = std::make_unique<VrlCutMediumGatherer>(scene, *tree, inputs.vrlSamples, inputs.cut, bounds());
                break;
            case MediumGathererKind::StochasticVrlCut:
                out.multiple = std::make_unique<StochasticVrlMediumGatherer>(stochastic());
                break;
            case MediumGathererKind::PlainVpls:
                out.multiple = std::make_unique<PlainVplMediumGatherer>(scene, lights, inputs.vplDistanceSamples);
                break;
            case MediumGathererKind::VplCut:
                out.multiple = std::make_unique<VplCutMediumGatherer>(scene, *tree, inputs.cut, inputs.vplDistanceSamples);
                break;
        }
    }
    if (transports.has(TransportPart::MediumSurface)) {
        switch (tree || !isCut(kinds.mediumSurface) ? kinds.mediumSurface : SurfaceGathererKind::PlainVrls) {
            case SurfaceGathererKind::PathSampled: break;
            case SurfaceGathererKind::PlainVrls:
                out.mediumSurface = std::make_unique<PlainVrlSurfaceGatherer>(scene, lights, inputs.vrlSamples);
                break;
            case SurfaceGathererKind::VrlCut:
                out.mediumSurface =
                    std::make_unique<VrlCutSurfaceGatherer>(scene, *tree, inputs.vrlSamples, inputs.cut, bounds());
                break;
            case SurfaceGathererKind::StochasticVrlCut:
                out.mediumSurface = std::make_unique<StochasticVrlSurfaceGatherer>(stochastic());
                break;
        }
    }
    const SurfaceVplLights* vpls = inputs.surfaceVpls;
    if (vpls && (transports.has(TransportPart::Single) ||
                 (transports.has(TransportPart::Surface) && !vpls->vpls.empty()))) {
        switch (kinds.surfaceVpls) {
            case SurfaceVplLightKind::None: break;
            case SurfaceVplLightKind::Plain:
                out.surfaceVpls = std::make_unique<PlainSurfaceVplLight>(scene, *vpls, inputs.cut);
                break;
            case SurfaceVplLightKind::Cut:  // without a tree (no VPL kept): every VPL, none
                if (vpls->tree.empty())
                    out.surfaceVpls = std::make_unique<PlainSurfaceVplLight>(scene, *vpls, inputs.cut);
                else
                    out.surfaceVpls = std::make_unique<SurfaceVplCutLight>(scene, *vpls, inputs.cut);
                break;
        }
    }
    return out;
}

size_t gathererBytesPerLight(const PartEstimators& kinds) {
    switch (kinds.multiple) {
        case MediumGathererKind::PlainVrls: return VrlLanes::kBytesPerVrl;
        case MediumGathererKind::VrlCut: return VrlCutBoundData::kBytesPerVrl;
        case MediumGathererKind::StochasticVrlCut: return VrlImportance::kBytesPerInnerNode;
        case MediumGathererKind::None:
        case MediumGathererKind::PlainVpls:
        case MediumGathererKind::VplCut: return 0;
    }
    return 0;
}

}  // namespace vrl
