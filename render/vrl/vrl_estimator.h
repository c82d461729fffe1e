// VrlEstimator: the contribution of one short VRL to one camera segment,
// Eq. 5 of Vibert et al. 2019 (Novak et al. 2012's joint importance sampling):
//   Phi sigma_s(v) f(v) sigma_s(u) f(u) T_r(u) T_r(w) V / (w^2 p(v) p(u|v)),
// with v on the VRL drawn with pdf proportional to 1/h(v) (h: distance to the
// camera ray's line; inverse CDF through asinh/sinh), then u on the camera
// segment by equiangular sampling from v. Isotropic media cancel the geometric
// term exactly; anisotropic (HG) media draw u from a piecewise-constant
// approximation of f(u) f(v) in the equiangular angle, mixed with the
// isotropic strategy (no tables are built for isotropic media).
// Degenerate configurations (parallel, crossing, touching, zero length) fall
// back to limiting pdfs: results stay finite and unbiased.
// The estimate itself is computed by the SIMD kernel (vrl_kernel.h: float lanes,
// the lines' geometry in double); the double-precision samplers below draw the
// same points from the same numbers and serve single scattering, part (c) and
// the tests that check the kernel sample by sample.
#pragma once

#include "render/core/rng.h"
#include "render/vrl/camera_segment.h"
#include "render/vrl/vrl.h"
#include "render/vrl/vrl_kernel.h"
#include "render/vrl/vrl_lanes.h"

#include <cstdint>

namespace vrl {

class Scene;

struct DistanceSample {
    float t = 0.0f;    // parameter along the line
    float pdf = 0.0f;  // per unit length; 0 if the interval is empty
};

// v on [0, vrl.length] with pdf proportional to 1/h(v), h = distance to the line
// (lineOrigin, lineDirection). Parallel lines: uniform.
DistanceSample sampleVrlPoint(const Vrl& vrl, const Vec3& lineOrigin, const Vec3& lineDirection, float xi);
float vrlPointPdf(const Vrl& vrl, const Vec3& lineOrigin, const Vec3& lineDirection, float v);

// u on [0, length] of the segment with pdf proportional to 1/|x(u) - point|^2.
DistanceSample sampleEquiangular(const Vec3& origin, const Vec3& direction, float length, const Vec3& point,
                                 float xi);
float equiangularPdf(const Vec3& origin, const Vec3& direction, float length, const Vec3& point, float u);

// The random stream of VRL `vrlIndex` for one camera segment (or surface point)
// `streamKey`: the same in plain and Lightcuts shading, so the two differ only by
// the cut's approximation.
inline Rng vrlStream(uint64_t streamKey, uint32_t vrlIndex) { return Rng(streamKey, vrlIndex); }

class VrlEstimator {
public:
    // Anisotropic media (either end HG): u's equiangular angle is drawn uniformly
    // with probability kHgUniformWeight, else from a kHgBins-bin piecewise-constant
    // fit of f(u) f(v) evaluated at the bins' centres. So the angle's pdf is at
    // least kHgUniformWeight / span everywhere, and at least
    // (kHgUniformWeight + (1 - kHgUniformWeight) min f / max f) / span: the HG
    // cluster bound (cluster_bound.h) rests on both.
    static constexpr int kHgBins = 8;
    static constexpr double kHgUniformWeight = 0.25;

    // samplesPerVrl: (u, v) pairs averaged per VRL and segment.
    VrlEstimator(const Scene& scene, int samplesPerVrl);

    // One estimate of the VRL's radiance contribution to the segment's origin end
    // (already multiplied by the segment's throughputBefore).
    // Computed by the SIMD kernel (vrl_kernel.h) in one lane; each sample draws
    // four numbers from `rng`.
    Rgb contribution(const Vrl& vrl, const CameraSegment& segment, Rng& rng) const;

    // Several contributions at once in SIMD lanes (the cuts' nodes): query k is
    // contribution(*vrl, segment, rng) with vrl's flux replaced by `flux` and rng =
    // vrlStream(streamKey, stream), written to out[k].
    struct Query {
        const Vrl* vrl;
        Rgb flux;
        uint32_t stream;
    };
    void contributions(const Query* queries, size_t count, const CameraSegment& segment, uint64_t streamKey,
                       Rgb* out) const;

    // contribution(vrls[indices[k]], segment, rng) for k < count into out[k], in SIMD
    // lanes, every number drawn from the one `rng`: batch by batch of lanes, each
    // sample lane by lane (the stochastic cut's drawn VRLs).
    void contributions(const Vrl* vrls, const int32_t* indices, size_t count, const CameraSegment& segment, Rng& rng,
                       Rgb* out) const;

    // The plain VRL method: the sum of contribution() over every VRL of `lanes`,
    // VRL k with vrlStream(streamKey, k), evaluated in SIMD lanes (no allocation
    // unless samplesPerVrl > 1).
    Rgb sumOverVrls(const VrlLanes& lanes, const CameraSegment& segment, uint64_t streamKey) const;

private:
    KernelSegment kernelSegment(const CameraSegment& segment) const;
    // contribution() of n <= kKernelPadding VRLs (flux replaced by fluxes[j], numbers
    // from rngs[j], four per sample) in one batch's lanes.
    void evaluateFew(const Vrl* const vrls[], const Rgb fluxes[], Rng* const rngs[], size_t n,
                     const CameraSegment& segment, Rgb* result) const;
    // Lane k's estimate, with the transmittance of a deferred lane.
    Rgb finish(const CameraSegment& segment, const KernelOutput& out, size_t k) const;

    const Scene& scene_;
    int samplesPerVrl_;
};

}  // namespace vrl
