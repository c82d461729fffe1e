// VRL kernel: the one-VRL estimate of VrlEstimator (vrl_estimator.h, Eq. 5 of
// Vibert et al. 2019) for many VRLs against one camera segment at once, in float
// SIMD lanes (Google Highway, dispatched at run time to the best instruction set
// of the machine: SSE2 ... AVX-512; any x86-64 runs it).
//
// Contract: lane k of a call evaluates VRL k against the segment with the four
// uniform numbers xi[0..3][k], exactly as one sample of VrlEstimator: v from the
// 1/h(v) pdf with xi[0]; u by equiangular sampling from v, in anisotropic media
// (either end HG) a mixture of that (weight kHgUniformWeight) with an
// kHgBins-bin fit of f(u) f(v): xi[1] picks the strategy, xi[2] the bin (or the
// uniform angle), xi[3] the point in the bin; isotropic lanes take the angle
// from xi[1]. Those are the numbers, in order, that the double-precision
// estimator this kernel replaced drew, so an image changes only by rounding.
// Output per lane: Phi sigma_s(v) f(v) f(u) T / (w^2 p(v) p(u|v)); the caller
// multiplies the sum by the segment's sigma_s(u) and throughputBefore. T is the
// closed form exp(-sigma_t (u + w)) when the VRL lies in the segment's medium
// and that medium needs no visibility; otherwise the lane is `deferred`: T is
// left out and the caller multiplies by T(u) and the scene's transmittance
// between x_u = o + u w and x_v (returned), or, in a scene without null
// surfaces, T keeps its closed form and the caller tests visibility only.
//
// Derivation of the cheaper forms (each exact in real arithmetic):
// * v: with a = s(0 - v0)/h, b = s(L - v0)/h, A = asinh a, B = asinh b and the
//   sampled point v = v0 + h/s sinh(A + xi (B - A)), sinh A = a gives
//     v = h/s (sinh(A + 2y) - sinh A) = h/s 2 cosh(A + y) sinh y,  y = xi (B - A)/2,
//   no cancellation between v0 and the offset (v0 can be 10^6 VRL lengths away);
//   with E = e^y = 1 + expm1(y) and X = e^A E: cosh(A + y) = (X + 1/X)/2 and
//   sinh y = expm1(y)(2 + expm1(y))/(2E). Its pdf s / ((B - A) h(v)) uses
//   h(v) = h cosh(A + 2y). B - A = log1p(e^B/e^A - 1) as in vrl_estimator.cpp.
//   The lines' distance h is |r . (d x w)| / |d x w| (a triple product: no
//   cancellation between |r_perp|^2 and its projection).
// * u: the span atan2(L h, h^2 - delta (L - delta)) = atan2(h, R^2/L - delta),
//   R^2 = h^2 + delta^2 (no overflow for the 10^30-long segments that leave an
//   unbounded medium); u = delta + h tan(theta_A + phi) = R^2 sin(phi) /
//   (h cos(phi) + delta sin(phi)) (the denominator is R cos(theta_A + phi) > 0).
//   Segments longer than 100 / min sigma_t (over channels that scatter) are
//   shortened to it: beyond, T < e^-100, below float's smallest number.
// * The bins' offset direction e = (w x r) x w / |w x r| is orthogonal to w to
//   float precision, as the HG cluster bound's cosine margins assume.
// Float suffices: the samplers' parameters (v0, h, delta) only shape the pdf,
// which is evaluated with the same parameters as the sample is drawn, and the
// geometry term uses the points themselves; tests/render/vrl/ compares the
// kernel with the double estimator it replaced and with quadrature.
#pragma once

#include <cstddef>
#include <cstdint>

namespace vrl {

// Inputs and outputs are arrays padded to a multiple of kKernelPadding lanes
// (the widest vector); padding lanes must have length 0 and evaluate to 0.
inline constexpr size_t kKernelPadding = 16;

struct KernelSegment {
    float origin[3];
    float direction[3];      // unit
    float perpendicular[3];  // a unit vector orthogonal to direction (for points on the line)
    float length = 0.0f;     // already shortened (see above)
    float g = 0.0f;          // the segment medium's HG g (0: isotropic)
    float sigmaT[3];         // the segment medium's extinction
    int32_t medium = -1;
    bool closedTransmittance = false;  // the segment's medium needs no visibility
    // The medium needs visibility but the scene has no null surfaces: a lane in the
    // segment's medium takes the closed form and is deferred for a visibility test only.
    bool visibilityOnly = false;
};

struct KernelVrls {  // structure of arrays, flux already times sigma_s(v)
    const float *originX, *originY, *originZ, *directionX, *directionY, *directionZ, *length, *g;
    const float *fluxR, *fluxG, *fluxB;
    const int32_t* medium;
};

struct KernelOutput {
    float *r, *g, *b;        // the lane's estimate (see the contract)
    float* u;                // the sampled point on the segment
    float *vX, *vY, *vZ;     // the sampled point on the VRL
    int32_t* deferred;       // 1: T is left out (see the contract); 2: only visibility is
                             // left out (KernelSegment::visibilityOnly)
};

// Evaluates lanes [0, count) (count rounded up to the vector width; the arrays
// hold at least that many). xi: four arrays of uniform numbers in [0, 1).
void evaluateVrlLanes(const KernelSegment& segment, const KernelVrls& vrls, const float* const xi[4],
                      const KernelOutput& out, size_t count);

// The instruction set the kernel dispatches to on this machine (e.g. "AVX2").
const char* vrlKernelTarget();

}  // namespace vrl
