#include "render/vrl/vrl_estimator.h"

#include "render/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace vrl {

namespace {

using V3d = Imath::V3d;
V3d toDouble(const Vec3& v) { return {v.x, v.y, v.z}; }

// Where the VRL's line comes closest to the camera line: h(v)^2 = h0^2 + s^2 (v - v0)^2.
struct LinePair {
    double v0 = 0, h0 = 0, sinTheta = 0;
    bool parallel = true;
    double epsilon = 0;  // floor for h0 in the pdf: keeps the pdf proper when the lines cross
};

LinePair linePair(const Vrl& vrl, const Vec3& lineOrigin, const Vec3& lineDirection) {
    const V3d w = toDouble(lineDirection), d = toDouble(vrl.direction), r = toDouble(vrl.origin - lineOrigin);
    const V3d rPerp = r - w * w.dot(r), dPerp = d - w * w.dot(d);
    LinePair p;
    p.epsilon = 1e-7 * (1.0 + r.length() + vrl.length);
    const double s2 = dPerp.length2();
    if (s2 < 1e-14) {  // parallel within float precision: h is constant
        p.h0 = rPerp.length();
        return p;
    }
    p.parallel = false;
    p.sinTheta = std::sqrt(s2);
    p.v0 = -rPerp.dot(dPerp) / s2;
    p.h0 = std::sqrt(std::max(0.0, rPerp.length2() - rPerp.dot(dPerp) * rPerp.dot(dPerp) / s2));
    return p;
}

// The asinh parametrisation of the VRL: A = asinh(a), B = asinh(b) with
// a = s (0 - v0) / h, b = s (L - v0) / h, and the point v = v0 + h/s sinh(A + xi (B - A)).
// Computed without asinh and sinh: with E(x) = e^asinh(x) = x + sqrt(x^2 + 1) (for
// x < 0 as 1 / (sqrt(x^2 + 1) - x), free of cancellation), and r_x = sqrt(x^2 + 1),
//   e^B / e^A - 1 = (b - a) (1 + (a + b) / (r_a + r_b)) / E(a)        (a + b >= 0)
//                 = (b - a) (1 - (a + b) / (r_a + r_b)) / (r_b - b)  (a + b < 0)
// exactly (the one whose bracket lies in [1, 2]: no cancellation, also for the
// large |a|, |b| of a VRL almost parallel to the camera line), so
// B - A = log1p of that (accurate also when a and b are close), and
// sinh(A + xi (B - A)) = (X - 1/X) / 2 with X = E(a) e^(xi (B - A)): one log1p and
// one exp where asinh, asinh, sinh took three logarithm-class calls and an exp.
struct AsinhRange {
    double span, expA, h;  // B - A, e^A, h floored
    // sinh(A + xi (B - A)).
    double sinhAt(double xi) const {
        const double x = expA * std::exp(xi * span);
        return 0.5 * (x - 1.0 / x);
    }
};
AsinhRange asinhRange(const LinePair& p, double length) {
    const double h = std::max(p.h0, p.epsilon);
    const double a = p.sinTheta * (0.0 - p.v0) / h, b = p.sinTheta * (length - p.v0) / h;
    const double ra = std::sqrt(a * a + 1.0), rb = std::sqrt(b * b + 1.0);
    const double expA = a >= 0.0 ? a + ra : 1.0 / (ra - a);
    const double sum = (a + b) / (ra + rb);
    const double ratioMinusOne = a + b >= 0.0 ? (b - a) * (1.0 + sum) / expA : (b - a) * (1.0 - sum) / (rb - b);
    return {std::log1p(ratioMinusOne), expA, h};
}

struct Equiangular {
    double delta, h, thetaA, thetaB;
};
Equiangular equiangular(const Vec3& origin, const Vec3& direction, float length, const Vec3& point) {
    const V3d w = toDouble(direction), r = toDouble(point - origin);
    const double delta = w.dot(r);
    const double distance = (r - w * delta).length();
    // Floor against exact hits on the line, relative to the point's own scale (not the
    // segment's: a ray leaving an unbounded medium is 1e30 long).
    const double h = std::max(distance, 1e-7 * (1.0 + r.length()));
    return {delta, h, std::atan2(0.0 - delta, h), std::atan2(double(length) - delta, h)};
}

}  // namespace

DistanceSample sampleVrlPoint(const Vrl& vrl, const Vec3& lineOrigin, const Vec3& lineDirection, float xi) {
    if (!(vrl.length > 0.0f)) return {};
    const LinePair p = linePair(vrl, lineOrigin, lineDirection);
    if (p.parallel) return {xi * vrl.length, 1.0f / vrl.length};
    const AsinhRange a = asinhRange(p, vrl.length);
    if (!(a.span > 0.0) || !std::isfinite(a.span)) return {xi * vrl.length, 1.0f / vrl.length};
    // Round to the float returned first, so the pdf is that of the point returned.
    const double v = double(std::clamp(float(p.v0 + a.h / p.sinTheta * a.sinhAt(xi)), 0.0f, vrl.length));
    const double pdf = p.sinTheta / (a.span * std::sqrt(a.h * a.h + p.sinTheta * p.sinTheta * (v - p.v0) * (v - p.v0)));
    return {float(v), float(pdf)};
}

float vrlPointPdf(const Vrl& vrl, const Vec3& lineOrigin, const Vec3& lineDirection, float v) {
    if (!(vrl.length > 0.0f) || v < 0.0f || v > vrl.length) return 0.0f;
    const LinePair p = linePair(vrl, lineOrigin, lineDirection);
    if (p.parallel) return 1.0f / vrl.length;
    const AsinhRange a = asinhRange(p, vrl.length);
    if (!(a.span > 0.0) || !std::isfinite(a.span)) return 1.0f / vrl.length;
    return float(p.sinTheta / (a.span * std::sqrt(a.h * a.h + p.sinTheta * p.sinTheta * (v - p.v0) * (v - p.v0))));
}

DistanceSample sampleEquiangular(const Vec3& origin, const Vec3& direction, float length, const Vec3& point,
                                 float xi) {
    if (!(length > 0.0f)) return {};
    const Equiangular e = equiangular(origin, direction, length, point);
    if (!(e.thetaB > e.thetaA)) return {xi * length, 1.0f / length};
    const double u =
        double(std::clamp(float(e.delta + e.h * std::tan(e.thetaA + xi * (e.thetaB - e.thetaA))), 0.0f, length));
    const double pdf = e.h / ((e.thetaB - e.thetaA) * (e.h * e.h + (u - e.delta) * (u - e.delta)));
    return {float(u), float(pdf)};
}

float equiangularPdf(const Vec3& origin, const Vec3& direction, float length, const Vec3& point, float u) {
    if (!(length > 0.0f) || u < 0.0f || u > length) return 0.0f;
    const Equiangular e = equiangular(origin, direction, length, point);
    if (!(e.thetaB > e.thetaA)) return 1.0f / length;
    return float(e.h / ((e.thetaB - e.thetaA) * (e.h * e.h + (u - e.delta) * (u - e.delta))));
}

VrlEstimator::VrlEstimator(const Scene& scene, int samplesPerVrl)
    : scene_(scene), samplesPerVrl_(std::max(1, samplesPerVrl)) {}

KernelSegment VrlEstimator::kernelSegment(const CameraSegment& segment) const {
    const HomogeneousMedium& medium = scene_.media()[size_t(segment.medium)];
    KernelSegment k;
    const Vec3 perpendicular = Frame::fromNormal(segment.direction).s;
    for (int i = 0; i < 3; ++i) {
        k.origin[i] = segment.origin[i];
        k.direction[i] = segment.direction[i];
        k.perpendicular[i] = perpendicular[i];
        k.sigmaT[i] = medium.sigmaT()[i];
    }
    // Beyond 100 mean free paths of the least extinct channel that scatters, T(u) < e^-100:
    // the kernel's segment ends there (the 10^30-long rays of unbounded media).
    float sigmaMin = kInfinity;
    for (int i = 0; i < 3; ++i)
        if (medium.sigmaS()[i] > 0.0f) sigmaMin = std::min(sigmaMin, medium.sigmaT()[i]);
    k.length = sigmaMin > 0.0f && sigmaMin < kInfinity ? std::min(segment.length, 100.0f / sigmaMin) : segment.length;
    k.g = medium.phase().g();
    k.medium = segment.medium;
    k.closedTransmittance = !scene_.mediumNeedsVisibility(segment.medium);
    k.visibilityOnly = !k.closedTransmittance && !scene_.hasNullSurfaces();
    return k;
}

Rgb VrlEstimator::finish(const CameraSegment& segment, const KernelOutput& out, size_t k) const {
    Rgb value(out.r[k], out.g[k], out.b[k]);
    if (!out.deferred[k] || isBlack(value)) return value;
    const Vec3 xu = segment.origin + segment.direction * out.u[k], xv(out.vX[k], out.vY[k], out.vZ[k]);
    if (out.deferred[k] == 2) return scene_.visible(xu, xv) ? value : Rgb(0.0f);
    return value * scene_.media()[size_t(segment.medium)].transmittance(out.u[k]) *
           scene_.transmittance(xu, xv, segment.medium);
}

void VrlEstimator::evaluateFew(const Vrl* const vrls[], const Rgb fluxes[], Rng* const rngs[], size_t n,
                               const CameraSegment& segment, Rgb* result) const {
    // n <= kKernelPadding VRLs in the lanes of one padded batch (zero-length VRLs after them).
    constexpr size_t P = kKernelPadding;
    alignas(64) float in[VrlLanes::kArrays][P] = {};
    alignas(64) int32_t media[P] = {};
    alignas(64) float xi[4][P] = {};
    alignas(64) float r[P], g[P], b[P], u[P], vx[P], vy[P], vz[P];
    alignas(64) int32_t deferred[P];
    float* arrays[VrlLanes::kArrays];
    for (int a = 0; a < VrlLanes::kArrays; ++a) arrays[a] = in[a];
    for (size_t j = 0; j < n; ++j) {
        Vrl vrl = *vrls[j];
        vrl.flux = fluxes[j];
        VrlLanes::write(vrl, scene_, arrays, media, j);
    }
    const float* const numbers[4] = {xi[0], xi[1], xi[2], xi[3]};
    const KernelOutput out{r, g, b, u, vx, vy, vz, deferred};
    const KernelSegment k = kernelSegment(segment);
    Rgb sum[P];
    std::fill(sum, sum + P, Rgb(0.0f));
    for (int i = 0; i < samplesPerVrl_; ++i) {
        for (size_t j = 0; j < n; ++j)
            for (auto& x : xi) x[j] = rngs[j]->next();
        evaluateVrlLanes(k, VrlLanes::view(arrays, media), numbers, out, n);
        for (size_t j = 0; j < n; ++j) sum[j] += finish(segment, out, j);
    }
    const Rgb after = scene_.media()[size_t(segment.medium)].sigmaS() * segment.throughputBefore / float(samplesPerVrl_);
    for (size_t j = 0; j < n; ++j) result[j] = sum[j] * after;
}

Rgb VrlEstimator::contribution(const Vrl& vrl, const CameraSegment& segment, Rng& rng) const {
    if (!(vrl.length > 0.0f) || !(segment.length > 0.0f)) return Rgb(0.0f);
    const Vrl* const vrls[1] = {&vrl};
    const Rgb fluxes[1] = {vrl.flux};
    Rng* const rngs[1] = {&rng};
    Rgb result(0.0f);
    evaluateFew(vrls, fluxes, rngs, 1, segment, &result);
    return result;
}

void VrlEstimator::contributions(const Vrl* vrls, const int32_t* indices, size_t count, const CameraSegment& segment,
                                 Rng& rng, Rgb* out) const {
    if (!(segment.length > 0.0f)) {
        std::fill(out, out + count, Rgb(0.0f));
        return;
    }
    constexpr size_t P = kKernelPadding;
    for (size_t first = 0; first < count; first += P) {
        const size_t n = std::min(P, count - first);
        const Vrl* batch[P];
        Rgb fluxes[P];
        Rng* rngs[P];
        for (size_t j = 0; j < n; ++j) {
            batch[j] = &vrls[size_t(indices[first + j])];
            fluxes[j] = batch[j]->flux;
            rngs[j] = &rng;
        }
        evaluateFew(batch, fluxes, rngs, n, segment, out + first);
    }
}

void VrlEstimator::contributions(const Query* queries, size_t count, const CameraSegment& segment, uint64_t streamKey,
                                 Rgb* result) const {
    if (!(segment.length > 0.0f)) {
        std::fill(result, result + count, Rgb(0.0f));
        return;
    }
    constexpr size_t P = kKernelPadding;
    for (size_t first = 0; first < count; first += P) {
        const size_t n = std::min(P, count - first);
        const Vrl* vrls[P];
        Rgb fluxes[P];
        std::optional<Rng> streams[P];
        Rng* rngs[P];
        for (size_t j = 0; j < n; ++j) {
            vrls[j] = queries[first + j].vrl;
            fluxes[j] = queries[first + j].flux;
            rngs[j] = &streams[j].emplace(vrlStream(streamKey, queries[first + j].stream));
        }
        evaluateFew(vrls, fluxes, rngs, n, segment, result + first);
    }
}

Rgb VrlEstimator::sumOverVrls(const VrlLanes& lanes, const CameraSegment& segment, uint64_t streamKey) const {
    if (!(segment.length > 0.0f) || lanes.size() == 0) return Rgb(0.0f);
    constexpr size_t kChunk = 16 * kKernelPadding;
    alignas(64) float xi[4][kChunk];
    alignas(64) float r[kChunk], g[kChunk], b[kChunk], u[kChunk], vx[kChunk], vy[kChunk], vz[kChunk];
    alignas(64) int32_t deferred[kChunk];
    const float* const numbers[4] = {xi[0], xi[1], xi[2], xi[3]};
    const KernelOutput out{r, g, b, u, vx, vy, vz, deferred};
    const KernelSegment k = kernelSegment(segment);
    double total[3] = {0.0, 0.0, 0.0};
    std::vector<Rng> streams;  // only for several samples per VRL
    for (size_t first = 0; first < lanes.size(); first += kChunk) {
        const size_t count = std::min(kChunk, lanes.size() - first);
        const KernelVrls vrls = lanes.from(first);
        if (samplesPerVrl_ == 1) {
            for (size_t j = 0; j < count; ++j) {
                Rng rng = vrlStream(streamKey, uint32_t(first + j));
                for (auto& x : xi) x[j] = rng.next();
            }
        } else {
            streams.clear();
            for (size_t j = 0; j < count; ++j) streams.push_back(vrlStream(streamKey, uint32_t(first + j)));
        }
        for (int i = 0; i < samplesPerVrl_; ++i) {
            if (samplesPerVrl_ > 1)
                for (size_t j = 0; j < count; ++j)
                    for (auto& x : xi) x[j] = streams[j].next();
            for (size_t j = count; j < (count + kKernelPadding - 1) / kKernelPadding * kKernelPadding; ++j)
                for (auto& x : xi) x[j] = 0.0f;
            evaluateVrlLanes(k, vrls, numbers, out, count);
            for (size_t j = 0; j < count; ++j) {
                const Rgb value = deferred[j] ? finish(segment, out, j) : Rgb(r[j], g[j], b[j]);
                total[0] += value.x, total[1] += value.y, total[2] += value.z;
            }
        }
    }
    const Rgb sum(float(total[0] / samplesPerVrl_), float(total[1] / samplesPerVrl_), float(total[2] / samplesPerVrl_));
    return sum * scene_.media()[size_t(segment.medium)].sigmaS() * segment.throughputBefore;
}

}  // namespace vrl
