#include "render/vrl/vrl_estimator.h"

#include "render/scene/scene.h"

#include <algorithm>
#include <array>
#include <cmath>

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

// Equiangular sampling of the camera segment from xv in the angle phi measured
// from the segment's start, phi in [0, span): u - delta = h tan(thetaA + phi).
// With t_a = tan(thetaA) = -delta / h, the span thetaB - thetaA is one atan2,
// atan2(L h, h^2 - delta (L - delta)) (the tangent difference formula; its sine
// part L h > 0 puts it in (0, pi) as the span is), and
// tan(thetaA + phi) = (t_a + tan phi) / (1 - t_a tan phi), so neither angle is formed:
// one atan2 and one tan per estimate where two atan2 and a tan were.
struct EquiangularSpan {
    double delta, h, span;
    double offsetAt(double phi) const {  // u - delta
        const double t = std::tan(phi);
        return h * (h * t - delta) / (h + delta * t);
    }
};
EquiangularSpan equiangularSpan(const Vec3& origin, const Vec3& direction, float length, const Vec3& point) {
    const V3d w = toDouble(direction), r = toDouble(point - origin);
    const double delta = w.dot(r);
    const double distance = (r - w * delta).length();
    const double h = std::max(distance, 1e-7 * (1.0 + r.length()));  // as equiangular()
    const double L = double(length);
    return {delta, h, std::atan2(L * h, h * h - delta * (L - delta))};
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

Rgb VrlEstimator::contribution(const Vrl& vrl, const CameraSegment& segment, Rng& rng) const {
    if (!(vrl.length > 0.0f) || !(segment.length > 0.0f)) return Rgb(0.0f);
    Rgb sum(0.0f);
    for (int i = 0; i < samplesPerVrl_; ++i) sum += sampleOnce(vrl, segment, rng);
    return sum / float(samplesPerVrl_);
}

Rgb VrlEstimator::sampleOnce(const Vrl& vrl, const CameraSegment& segment, Rng& rng) const {
    const HomogeneousMedium& mediumV = scene_.media()[vrl.medium];
    const HomogeneousMedium& mediumU = scene_.media()[segment.medium];
    const DistanceSample vs = sampleVrlPoint(vrl, segment.origin, segment.direction, rng.next());
    if (!(vs.pdf > 0.0f)) return Rgb(0.0f);
    const Vec3 xv = vrl.origin + vrl.direction * vs.t;

    // u | v: equiangular from xv, or for anisotropic media a mixture of that with a
    // piecewise-constant fit of f(u) f(v) over kBins bins of the equiangular angle.
    const EquiangularSpan e = equiangularSpan(segment.origin, segment.direction, segment.length, xv);
    const double span = e.span;
    if (!(span > 0.0)) return Rgb(0.0f);
    const bool anisotropic = !mediumU.phase().isIsotropic() || !mediumV.phase().isIsotropic();
    constexpr int kBins = kHgBins;
    constexpr double kUniformWeight = kHgUniformWeight;
    std::array<double, kBins> binWeight{};
    double binTotal = 0.0;
    if (anisotropic) {
        // In the plane of the camera line and xv, the direction from xv to u(theta) is
        // w sin(theta) - e cos(theta), e the unit offset of xv from the line: so
        // cos to the VRL = sin(theta) (d.w) - cos(theta) (d.e), cos to the camera = -sin(theta).
        // e in double, orthogonal to w to double precision: a float foot point would tilt
        // it towards w and scale the bins' cosines (the HG cluster bound relies on them).
        const Imath::V3d w = Imath::V3d(segment.direction.x, segment.direction.y, segment.direction.z).normalized();
        const Imath::V3d r(double(xv.x) - segment.origin.x, double(xv.y) - segment.origin.y,
                           double(xv.z) - segment.origin.z);
        const Imath::V3d offset = r - w * w.dot(r);
        const double offsetLength = offset.length();
        const Vec3 frameS = Frame::fromNormal(segment.direction).s;
        const Imath::V3d unitOffset = offsetLength > 0.0 ? offset / offsetLength : Imath::V3d(frameS.x, frameS.y, frameS.z);
        const Imath::V3d d(vrl.direction.x, vrl.direction.y, vrl.direction.z);
        const double dw = d.dot(w), de = d.dot(unitOffset);
        const double step = span / kBins;
        // cos, sin of thetaA + step / 2 (cos thetaA = h / r, sin thetaA = -delta / r), then
        // rotated by step per bin (one sincos pair); only here, not for isotropic media.
        const double radius = std::sqrt(e.h * e.h + e.delta * e.delta);
        const double cosA = e.h / radius, sinA = -e.delta / radius;
        const double cHalf = std::cos(0.5 * step), sHalf = std::sin(0.5 * step);
        const double cStep = cHalf * cHalf - sHalf * sHalf, sStep = 2.0 * sHalf * cHalf;
        double c = cosA * cHalf - sinA * sHalf, s = sinA * cHalf + cosA * sHalf;
        for (int b = 0; b < kBins; ++b) {
            binWeight[b] = double(mediumV.phase().evalCosine(float(s * dw - c * de)) * mediumU.phase().evalCosine(float(-s)));
            binTotal += binWeight[b];
            const double cNext = c * cStep - s * sStep;
            s = s * cStep + c * sStep;
            c = cNext;
        }
    }
    double phi;  // the angle from thetaA
    if (anisotropic && binTotal > 0.0 && rng.next() >= kUniformWeight) {
        double target = rng.next() * binTotal;
        int b = 0;
        while (b < kBins - 1 && target >= binWeight[b]) target -= binWeight[b++];
        phi = (b + rng.next()) * span / kBins;
    } else {
        phi = rng.next() * span;
    }
    phi = std::clamp(phi, 0.0, span);
    double thetaPdf = 1.0 / span;  // density in the angle
    if (anisotropic && binTotal > 0.0) {
        const int b = std::min(kBins - 1, int(phi / span * kBins));
        thetaPdf = kUniformWeight / span + (1.0 - kUniformWeight) * binWeight[b] / binTotal * kBins / span;
    }
    const double u = double(std::clamp(float(e.delta + e.offsetAt(phi)), 0.0f, segment.length));
    const double uPdf = thetaPdf * e.h / (e.h * e.h + (u - e.delta) * (u - e.delta));

    const Vec3 xu = segment.origin + segment.direction * float(u);
    const Vec3 d = xu - xv;
    const float w2 = d.length2();
    if (!(w2 > 0.0f)) return Rgb(0.0f);
    const float w = std::sqrt(w2);
    const Vec3 toU = d / w;
    const float phase = mediumV.phase().eval(vrl.direction, toU) * mediumU.phase().eval(toU, -segment.direction);
    // In one medium with nothing to occlude, T(u) T(w) = T(u + w): one exponential.
    const Rgb transmittance = vrl.medium == segment.medium && !scene_.mediumNeedsVisibility(segment.medium)
                                  ? mediumU.transmittance(float(u) + w)
                                  : mediumU.transmittance(float(u)) * scene_.transmittance(xu, xv, segment.medium);
    if (isBlack(transmittance)) return Rgb(0.0f);
    const double scale = double(phase) / (double(w2) * double(vs.pdf) * uPdf);
    return vrl.flux * mediumV.sigmaS() * mediumU.sigmaS() * segment.throughputBefore * transmittance * float(scale);
}

}  // namespace vrl
