// The VRL kernel in SIMD lanes (contract and derivations: vrl_kernel.h).
// Highway compiles this file once per instruction set (foreach_target.h
// re-includes it) and picks one at run time.

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/vrl/vrl_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include "render/core/geometry.h"  // kPi, kInv4Pi
#include "render/vrl/vrl_estimator.h"
#include "render/vrl/vrl_kernel.h"

HWY_BEFORE_NAMESPACE();
namespace vrl {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;


template <class D, class V = hn::Vec<D>>
HWY_INLINE V Dot(V ax, V ay, V az, V bx, V by, V bz) {
    return hn::MulAdd(ax, bx, hn::MulAdd(ay, by, hn::Mul(az, bz)));
}

// HG's density for the cosine, as PhaseFunction::evalCosine computes it (g = 0:
// exactly 1 / (4 pi)).
template <class D, class V = hn::Vec<D>>
HWY_INLINE V Hg(D d, V g, V g2, V cosTheta) {
    const V denom = hn::Sub(hn::Add(hn::Set(d, 1.0f), g2), hn::Mul(hn::Add(g, g), cosTheta));
    return hn::Div(hn::Mul(hn::Set(d, kInv4Pi), hn::Sub(hn::Set(d, 1.0f), g2)), hn::Mul(denom, hn::Sqrt(denom)));
}

// atan2(y, x) for y > 0: in (0, pi), from atan of a ratio of magnitude <= 1.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V AtanOfPositiveY(D d, V y, V x) {
    const auto yLarger = hn::Ge(y, hn::Abs(x));
    const V a = hn::Atan(d, hn::IfThenElse(yLarger, hn::Div(x, y), hn::Div(y, hn::IfThenElse(yLarger, y, x))));
    const V whenX = hn::IfThenElse(hn::Gt(x, hn::Zero(d)), a, hn::Add(hn::Set(d, kPi), a));
    return hn::IfThenElse(yLarger, hn::Sub(hn::Set(d, 0.5f * kPi), a), whenX);
}

// The line pair of each VRL lane [first, first + lanes) and the segment's line, in
// double (float inputs: their products are exact): s = |d x w|, v0 (the VRL's
// parameter of closest approach), h0 (the lines' distance) and |r_perp| (the
// VRL origin's distance from the camera line). Float would lose h0 for lines
// 1e-5 from parallel (the cross product's rounding times |r|) and break the
// cancellation the cluster bounds rest on. s = 0 marks parallel lines.
template <class DD>
void LinePairLanes(DD dd, const KernelSegment& seg, const KernelVrls& in, size_t first, size_t lanes, float* sOut,
                   float* v0Out, float* h0Out, float* offsetOut) {
    const hn::Rebind<float, decltype(dd)> df;
    using VD = hn::Vec<decltype(dd)>;
    const VD wx = hn::Set(dd, seg.direction[0]), wy = hn::Set(dd, seg.direction[1]), wz = hn::Set(dd, seg.direction[2]);
    const VD ox = hn::Set(dd, seg.origin[0]), oy = hn::Set(dd, seg.origin[1]), oz = hn::Set(dd, seg.origin[2]);
    const VD zero = hn::Zero(dd);
    const auto load = [&](const float* p, size_t k) { return hn::PromoteTo(dd, hn::LoadU(df, p + first + k)); };
    for (size_t k = 0; k < lanes; k += hn::Lanes(dd)) {
        const VD dx = load(in.directionX, k), dy = load(in.directionY, k), dz = load(in.directionZ, k);
        const VD rx = hn::Sub(load(in.originX, k), ox), ry = hn::Sub(load(in.originY, k), oy),
                 rz = hn::Sub(load(in.originZ, k), oz);
        const VD wr = Dot<decltype(dd)>(wx, wy, wz, rx, ry, rz), wd = Dot<decltype(dd)>(wx, wy, wz, dx, dy, dz);
        const VD rpx = hn::NegMulAdd(wx, wr, rx), rpy = hn::NegMulAdd(wy, wr, ry), rpz = hn::NegMulAdd(wz, wr, rz);
        const VD dpx = hn::NegMulAdd(wx, wd, dx), dpy = hn::NegMulAdd(wy, wd, dy), dpz = hn::NegMulAdd(wz, wd, dz);
        const VD s2 = Dot<decltype(dd)>(dpx, dpy, dpz, dpx, dpy, dpz);
        const auto parallel = hn::Lt(s2, hn::Set(dd, 1e-14));
        const VD s2Safe = hn::IfThenElse(parallel, hn::Set(dd, 1.0), s2);
        const VD rd = Dot<decltype(dd)>(rpx, rpy, rpz, dpx, dpy, dpz);
        const VD rr = Dot<decltype(dd)>(rpx, rpy, rpz, rpx, rpy, rpz);
        const VD v0 = hn::Neg(hn::Div(rd, s2Safe));
        const VD h0 = hn::Sqrt(hn::Max(zero, hn::Sub(rr, hn::Div(hn::Mul(rd, rd), s2Safe))));
        const VD offset = hn::Sqrt(rr);
        hn::StoreU(hn::DemoteTo(df, hn::IfThenZeroElse(parallel, hn::Sqrt(s2Safe))), df, sOut + k);
        hn::StoreU(hn::DemoteTo(df, hn::IfThenZeroElse(parallel, v0)), df, v0Out + k);
        hn::StoreU(hn::DemoteTo(df, hn::IfThenElse(parallel, offset, h0)), df, h0Out + k);
        hn::StoreU(hn::DemoteTo(df, offset), df, offsetOut + k);
    }
}

// D: the float lanes (the widest for batches, 4 for one VRL: the same arithmetic
// per lane); DD: double lanes for the line geometry.
template <class D, class DD>
HWY_INLINE void EvaluateLanes(D d, DD dd, const KernelSegment& seg, const KernelVrls& in, const float* const xi[4],
                              const KernelOutput& out, size_t count) {
    const hn::RebindToSigned<decltype(d)> di;
    using V = hn::Vec<decltype(d)>;
    const size_t lanes = hn::Lanes(d);
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), half = hn::Set(d, 0.5f);
    const V ox = hn::Set(d, seg.origin[0]), oy = hn::Set(d, seg.origin[1]), oz = hn::Set(d, seg.origin[2]);
    const V wx = hn::Set(d, seg.direction[0]), wy = hn::Set(d, seg.direction[1]), wz = hn::Set(d, seg.direction[2]);
    const V px = hn::Set(d, seg.perpendicular[0]), py = hn::Set(d, seg.perpendicular[1]),
            pz = hn::Set(d, seg.perpendicular[2]);
    const V L = hn::Set(d, seg.length);
    const V gU = hn::Set(d, seg.g), gU2 = hn::Mul(gU, gU);
    const V sigmaT[3] = {hn::Set(d, seg.sigmaT[0]), hn::Set(d, seg.sigmaT[1]), hn::Set(d, seg.sigmaT[2])};
    const auto segmentMedium = hn::Set(di, seg.medium);
    constexpr int kBins = VrlEstimator::kHgBins;
    const V uniformWeight = hn::Set(d, float(VrlEstimator::kHgUniformWeight));

    for (size_t i = 0; i < count; i += lanes) {
        const V dx = hn::LoadU(d, in.directionX + i), dy = hn::LoadU(d, in.directionY + i),
                dz = hn::LoadU(d, in.directionZ + i);
        const V len = hn::LoadU(d, in.length + i);
        const V gV = hn::LoadU(d, in.g + i), gV2 = hn::Mul(gV, gV);
        const V xi0 = hn::LoadU(d, xi[0] + i), xi1 = hn::LoadU(d, xi[1] + i), xi2 = hn::LoadU(d, xi[2] + i),
                xi3 = hn::LoadU(d, xi[3] + i);
        const auto valid = hn::Gt(len, zero);

        // The lines' geometry in double (LinePairLanes): s, v0, h0, |r_perp|.
        alignas(64) float pairS[kKernelPadding], pairV0[kKernelPadding], pairH0[kKernelPadding],
            pairOffset[kKernelPadding];
        LinePairLanes(dd, seg, in, i, lanes, pairS, pairV0, pairH0, pairOffset);
        const V s = hn::Load(d, pairS), v0 = hn::Load(d, pairV0), h0 = hn::Load(d, pairH0);
        const auto notParallel = hn::Gt(s, zero);
        const V sSafe = hn::IfThenElse(notParallel, s, one);
        const V rx = hn::Sub(hn::LoadU(d, in.originX + i), ox), ry = hn::Sub(hn::LoadU(d, in.originY + i), oy),
                rz = hn::Sub(hn::LoadU(d, in.originZ + i), oz);
        const V rLength = hn::Sqrt(Dot<decltype(d)>(rx, ry, rz, rx, ry, rz));
        const V floorH = hn::Mul(hn::Set(d, 1e-7f), hn::Add(one, hn::Add(rLength, len)));
        const V h = hn::Max(h0, floorH);

        // v on the VRL, pdf proportional to 1 / h(v).
        const V sOverH = hn::Div(sSafe, h);
        const V a = hn::Mul(sOverH, hn::Neg(v0)), b = hn::Mul(sOverH, hn::Sub(len, v0));
        const V ra = hn::Sqrt(hn::MulAdd(a, a, one)), rb = hn::Sqrt(hn::MulAdd(b, b, one));
        const auto aPositive = hn::Ge(a, zero);
        const V expA = hn::IfThenElse(aPositive, hn::Add(a, ra), hn::Div(one, hn::Sub(ra, a)));
        const V sum = hn::Div(hn::Add(a, b), hn::Add(ra, rb));
        const auto sumPositive = hn::Ge(hn::Add(a, b), zero);
        // b - a = s L / h directly: a and b may agree in all their float digits (a VRL
        // almost parallel to the camera line, far from the closest approach).
        const V bMinusA = hn::Mul(sOverH, len);
        // e^-B = r_b - b, for b > 0 as 1 / (r_b + b) (r_b - b cancels to 0 in float from b ~ 4000).
        const V expMinusB = hn::IfThenElse(hn::Gt(b, zero), hn::Div(one, hn::Add(rb, b)), hn::Sub(rb, b));
        const V ratioMinusOne = hn::Div(hn::Mul(bMinusA, hn::IfThenElse(sumPositive, hn::Add(one, sum), hn::Sub(one, sum))),
                                        hn::IfThenElse(sumPositive, expA, expMinusB));
        const auto ratioFinite = hn::And(hn::IsFinite(ratioMinusOne), hn::Gt(ratioMinusOne, zero));
        const V spanV = hn::Log1p(d, hn::IfThenElse(ratioFinite, ratioMinusOne, one));
        const auto asinhOk = hn::And(hn::And(notParallel, ratioFinite), hn::And(hn::Gt(spanV, zero), hn::IsFinite(spanV)));
        const V y = hn::Mul(hn::Mul(xi0, spanV), half);
        const V em1 = hn::Expm1(d, y);
        const V E = hn::Add(one, em1);
        const V X1 = hn::Mul(expA, E), X2 = hn::Mul(X1, E);
        const V sinhY = hn::Div(hn::Mul(em1, hn::Add(hn::Set(d, 2.0f), em1)), hn::Add(E, E));
        const V vAsinh = hn::Mul(hn::Div(h, sSafe), hn::Mul(hn::Add(X1, hn::Div(one, X1)), sinhY));
        // h(v) of the drawn point: h cosh(A + 2y), the model distance below.
        const V hAsinh = hn::Mul(h, hn::Mul(half, hn::Add(X2, hn::Div(one, X2))));
        const V v = hn::IfThenElse(asinhOk, hn::Min(hn::Max(vAsinh, zero), len), hn::Min(hn::Mul(xi0, len), len));
        // p(v) h(v): s / (B - A), or h(v) / L where v is uniform.
        const V vx = hn::MulAdd(dx, v, hn::LoadU(d, in.originX + i)), vy = hn::MulAdd(dy, v, hn::LoadU(d, in.originY + i)),
                vz = hn::MulAdd(dz, v, hn::LoadU(d, in.originZ + i));

        // u on the segment: equiangular from x_v (or the HG mixture).
        const V qx = hn::Sub(vx, ox), qy = hn::Sub(vy, oy), qz = hn::Sub(vz, oz);
        const V delta = Dot<decltype(d)>(wx, wy, wz, qx, qy, qz);
        const V cx = hn::Sub(hn::Mul(wy, qz), hn::Mul(wz, qy)), cy = hn::Sub(hn::Mul(wz, qx), hn::Mul(wx, qz)),
                cz = hn::Sub(hn::Mul(wx, qy), hn::Mul(wy, qx));
        const V lineDistance = hn::Sqrt(Dot<decltype(d)>(cx, cy, cz, cx, cy, cz));
        const V qLength = hn::Sqrt(Dot<decltype(d)>(qx, qy, qz, qx, qy, qz));
        // The distance of x_v from the line, as a model of the point: the v sampler's
        // h(v) (exact for the unrounded point), |r_perp| for parallel lines, else
        // the rounded point's (floored against exact hits on the line).
        const V hPoint = hn::Max(lineDistance, hn::Mul(hn::Set(d, 1e-7f), hn::Add(one, qLength)));
        const V hParallel = hn::Max(hn::Load(d, pairOffset), floorH);
        const V hu = hn::IfThenElse(asinhOk, hAsinh, hn::IfThenElse(notParallel, hPoint, hParallel));
        const V pdfVTimesH = hn::IfThenElse(asinhOk, hn::Div(sSafe, spanV), hn::Div(hu, hn::IfThenElse(valid, len, one)));
        const V R2 = hn::MulAdd(hu, hu, hn::Mul(delta, delta));
        const V spanU = AtanOfPositiveY(d, hu, hn::Sub(hn::Div(R2, L), delta));
        const auto spanOk = hn::Gt(spanU, zero);

        V thetaPdf = hn::Div(one, spanU);
        V phi = hn::Mul(xi1, spanU);
        const auto anisotropic = hn::Or(hn::Ne(gV, zero), hn::Ne(gU, zero));
        if (!hn::AllFalse(d, hn::And(anisotropic, valid))) {
            // The bins: directions from x_v to u(theta) are w sin(theta) - e cos(theta),
            // e the unit offset of x_v from the line, (w x q) x w / |w x q|.
            const auto onLine = hn::Eq(lineDistance, zero);
            const V invDistance = hn::Div(one, hn::IfThenElse(onLine, one, lineDistance));
            const V ex = hn::IfThenElse(onLine, px, hn::Mul(hn::Sub(hn::Mul(cy, wz), hn::Mul(cz, wy)), invDistance));
            const V ey = hn::IfThenElse(onLine, py, hn::Mul(hn::Sub(hn::Mul(cz, wx), hn::Mul(cx, wz)), invDistance));
            const V ez = hn::IfThenElse(onLine, pz, hn::Mul(hn::Sub(hn::Mul(cx, wy), hn::Mul(cy, wx)), invDistance));
            const V de = Dot<decltype(d)>(dx, dy, dz, ex, ey, ez), wd = Dot<decltype(d)>(dx, dy, dz, wx, wy, wz);
            const V step = hn::Mul(spanU, hn::Set(d, 1.0f / kBins));
            const V radius = hn::Sqrt(R2);
            const V cosA = hn::Div(hu, radius), sinA = hn::Neg(hn::Div(delta, radius));
            const V halfStep = hn::Mul(half, step);
            const V cHalf = hn::Cos(d, halfStep), sHalf = hn::Sin(d, halfStep);
            const V cStep = hn::Sub(hn::Mul(cHalf, cHalf), hn::Mul(sHalf, sHalf));
            const V sStep = hn::Mul(hn::Add(sHalf, sHalf), cHalf);
            V c = hn::Sub(hn::Mul(cosA, cHalf), hn::Mul(sinA, sHalf));
            V sn = hn::Add(hn::Mul(sinA, cHalf), hn::Mul(cosA, sHalf));
            V weight[kBins];
            V total = zero;
            for (int k = 0; k < kBins; ++k) {
                weight[k] = hn::Mul(Hg(d, gV, gV2, hn::Sub(hn::Mul(sn, wd), hn::Mul(c, de))), Hg(d, gU, gU2, hn::Neg(sn)));
                total = hn::Add(total, weight[k]);
                const V cNext = hn::Sub(hn::Mul(c, cStep), hn::Mul(sn, sStep));
                sn = hn::Add(hn::Mul(sn, cStep), hn::Mul(c, sStep));
                c = cNext;
            }
            const auto mixture = hn::And(anisotropic, hn::Gt(total, zero));
            const auto useBins = hn::And(mixture, hn::Ge(xi1, uniformWeight));
            // The bin: walk the weights as the scalar estimator did.
            V remaining = hn::Mul(xi2, total);
            V bin = zero;
            auto walking = hn::Ge(remaining, weight[0]);
            for (int k = 0; k < kBins - 1; ++k) {
                walking = hn::And(walking, hn::Ge(remaining, weight[k]));
                remaining = hn::IfThenElse(walking, hn::Sub(remaining, weight[k]), remaining);
                bin = hn::IfThenElse(walking, hn::Add(bin, one), bin);
            }
            const V phiBins = hn::Mul(hn::Add(bin, xi3), step);
            phi = hn::IfThenElse(useBins, phiBins, hn::IfThenElse(mixture, hn::Mul(xi2, spanU), phi));
            phi = hn::Min(hn::Max(phi, zero), spanU);
            const V binOfPhi = hn::Min(hn::Set(d, float(kBins - 1)), hn::Floor(hn::Mul(hn::Div(phi, spanU), hn::Set(d, float(kBins)))));
            V picked = zero;
            for (int k = 0; k < kBins; ++k) picked = hn::IfThenElse(hn::Eq(binOfPhi, hn::Set(d, float(k))), weight[k], picked);
            const V mixed = hn::Div(hn::MulAdd(hn::Sub(one, uniformWeight),
                                               hn::Mul(hn::Div(picked, hn::IfThenElse(mixture, total, one)), hn::Set(d, float(kBins))),
                                               uniformWeight),
                                    spanU);
            thetaPdf = hn::IfThenElse(mixture, mixed, thetaPdf);
        } else {
            phi = hn::Min(phi, spanU);
        }
        const V sinPhi = hn::Sin(d, phi), cosPhi = hn::Cos(d, phi);
        const V denominator = hn::MulAdd(hu, cosPhi, hn::Mul(delta, sinPhi));
        const V uRaw = hn::Div(hn::Mul(R2, sinPhi), hn::IfThenElse(hn::Gt(denominator, zero), denominator, one));
        const V u = hn::Max(zero, hn::IfThenElse(hn::Gt(denominator, zero), hn::Min(uRaw, L), L));

        const V tx = hn::Sub(hn::MulAdd(wx, u, ox), vx), ty = hn::Sub(hn::MulAdd(wy, u, oy), vy),
                tz = hn::Sub(hn::MulAdd(wz, u, oz), vz);
        const V w2 = Dot<decltype(d)>(tx, ty, tz, tx, ty, tz);
        const auto distanceOk = hn::Gt(w2, zero);
        const V wLength = hn::Sqrt(w2);
        const V invW = hn::Div(one, hn::IfThenElse(distanceOk, wLength, one));
        const V cosV = hn::Mul(Dot<decltype(d)>(dx, dy, dz, tx, ty, tz), invW);
        const V cosU = hn::Neg(hn::Mul(Dot<decltype(d)>(tx, ty, tz, wx, wy, wz), invW));
        const V phase = hn::Mul(Hg(d, gV, gV2, cosV), Hg(d, gU, gU2, cosU));
        // 1 / (w^2 p(v) p(u|v)) with p(u|v) = p(theta) h / w^2 (w^2 = h^2 + (u - delta)^2,
        // the model's distance, exact for the unrounded points): h(v) cancels.
        const V scale = hn::Div(phase, hn::Mul(pdfVTimesH, thetaPdf));
        const auto ok = hn::And(hn::And(valid, spanOk), hn::And(distanceOk, hn::Gt(pdfVTimesH, zero)));

        const auto sameMedium = hn::RebindMask(d, hn::Eq(hn::LoadU(di, in.medium + i), segmentMedium));
        const auto closed = seg.closedTransmittance || seg.visibilityOnly ? sameMedium : hn::And(sameMedium, hn::Lt(zero, zero));
        const V travelled = hn::Add(u, wLength);
        const float* flux[3] = {in.fluxR + i, in.fluxG + i, in.fluxB + i};
        float* target[3] = {out.r + i, out.g + i, out.b + i};
        for (int channel = 0; channel < 3; ++channel) {
            const V transmittance = hn::IfThenElse(closed, hn::Exp(d, hn::Neg(hn::Mul(sigmaT[channel], travelled))), one);
            const V weighted = hn::Mul(hn::LoadU(d, flux[channel]), transmittance);
            hn::StoreU(hn::IfThenElseZero(hn::And(ok, hn::Gt(weighted, zero)), hn::Mul(weighted, scale)), d, target[channel]);
        }
        hn::StoreU(u, d, out.u + i);
        hn::StoreU(vx, d, out.vX + i);
        hn::StoreU(vy, d, out.vY + i);
        hn::StoreU(vz, d, out.vZ + i);
        // 0: done; 1: T deferred; 2: visibility deferred.
        const auto deferT = hn::RebindMask(di, hn::AndNot(closed, ok));
        const auto deferVisibility = hn::RebindMask(di, hn::And(closed, ok));
        hn::StoreU(hn::IfThenElse(deferT, hn::Set(di, 1), hn::IfThenElseZero(deferVisibility, hn::Set(di, seg.visibilityOnly ? 2 : 0))),
                   di, out.deferred + i);
    }
}

void EvaluateVrlLanes(const KernelSegment& seg, const KernelVrls& in, const float* const xi[4],
                      const KernelOutput& out, size_t count) {
    if (count <= 4) {  // one VRL (the cuts): four lanes waste less than sixteen
        EvaluateLanes(hn::CappedTag<float, 4>(), hn::CappedTag<double, 2>(), seg, in, xi, out, count);
        return;
    }
    EvaluateLanes(hn::ScalableTag<float>(), hn::ScalableTag<double>(), seg, in, xi, out, count);
}

}  // namespace HWY_NAMESPACE
}  // namespace vrl
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vrl {

HWY_EXPORT(EvaluateVrlLanes);

void evaluateVrlLanes(const KernelSegment& segment, const KernelVrls& vrls, const float* const xi[4],
                      const KernelOutput& out, size_t count) {
    HWY_DYNAMIC_DISPATCH(EvaluateVrlLanes)(segment, vrls, xi, out, count);
}

const char* vrlKernelTarget() {
    // HWY_DYNAMIC_DISPATCH's choice: the best target both compiled in and supported
    // (targets are bits, a lower bit a better target).
    const int64_t available = hwy::SupportedTargets() & HWY_TARGETS;
    return available == 0 ? hwy::TargetName(HWY_STATIC_TARGET) : hwy::TargetName(available & -available);
}

}  // namespace vrl
#endif
