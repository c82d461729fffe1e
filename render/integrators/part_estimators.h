// PartEstimators: which estimator takes each transport part that virtual lights
// carry (transport_integrator.h's (a)-(d)). A method's row of the method table
// (render/render_method.h) holds one; TransportIntegrator builds its gatherers
// from it (gatherers.h), so a new estimator is a kind here and a class there.
#pragma once

#include <cstdint>

namespace vrl {

// Part (d), medium to medium, along each camera segment (MediumGatherer).
enum class MediumGathererKind : uint8_t {
    None,              // no virtual lights: the path tracer renders the whole image (the path method)
    PlainVrls,         // every VRL against the segment, in SIMD lanes
    VrlCut,            // a Lightcut through the VRL tree (VRL Lightcuts, the paper's method)
    StochasticVrlCut,  // a stochastic cut through the VRL tree, one VRL drawn under each node
    PlainVpls,         // every VPL gathered at stratified distance samples of the segment
    VplCut,            // a Lightcut through the VPL tree at each distance sample (the paper's baseline)
};

// Part (c), a medium lighting the surface the camera path reaches (SurfaceGatherer).
enum class SurfaceGathererKind : uint8_t {
    PathSampled,       // path-traced with (a) and (b) (the VPL methods: their lights are points)
    PlainVrls,         // every VRL at the surface point(s)
    VrlCut,            // a Lightcut through the VRL tree, shared with (d)
    StochasticVrlCut,  // a stochastic cut through the VRL tree, shared with (d)
};

// Surface VPLs (SurfaceVplLight): part (b)'s light that a surface reflects by a
// non-Dirac lobe into a camera segment, and part (a)'s share of x2's non-Dirac
// reflection, sampled down their tree per camera sample whatever the kind.
enum class SurfaceVplLightKind : uint8_t {
    None,   // (a) and (b) path-sample that light
    Plain,  // (b): every surface VPL against each camera segment
    Cut,    // (b): a Lightcut over the surface VPLs' tree
};

struct PartEstimators {
    MediumGathererKind multiple = MediumGathererKind::VrlCut;         // (d)
    SurfaceGathererKind mediumSurface = SurfaceGathererKind::VrlCut;  // (c)
    SurfaceVplLightKind surfaceVpls = SurfaceVplLightKind::Cut;       // (b)'s surface light, (a)'s share

    // (c) and (d) are Monte Carlo estimates per camera sample (averaged like (a), (b)),
    // not values computed once per pixel.
    constexpr bool perSample() const {
        return multiple == MediumGathererKind::StochasticVrlCut ||
               mediumSurface == SurfaceGathererKind::StochasticVrlCut;
    }
    // (c) comes from the VRLs rather than the path tracer.
    constexpr bool vrlLitSurfaces() const { return mediumSurface != SurfaceGathererKind::PathSampled; }
};

// A kind that walks a cut through a light tree (and so needs one, and counts its nodes).
constexpr bool isCut(MediumGathererKind k) {
    return k == MediumGathererKind::VrlCut || k == MediumGathererKind::StochasticVrlCut ||
           k == MediumGathererKind::VplCut;
}
constexpr bool isCut(SurfaceGathererKind k) {
    return k == SurfaceGathererKind::VrlCut || k == SurfaceGathererKind::StochasticVrlCut;
}
constexpr bool isStochastic(MediumGathererKind k) { return k == MediumGathererKind::StochasticVrlCut; }
constexpr bool isStochastic(SurfaceGathererKind k) { return k == SurfaceGathererKind::StochasticVrlCut; }

}  // namespace vrl
