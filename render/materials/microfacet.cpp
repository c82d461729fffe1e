#include "render/materials/microfacet.h"

#include <Imath/ImathVec.h>

#include <algorithm>
#include <cmath>

namespace vrl {

namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr double kInvSqrtPi = 0.56418958354775628695;

// Inverse error function in double: Giles' (2010) single-precision polynomial
// as a start, refined by Newton steps on erf.
double erfInv(double y) {
    y = std::clamp(y, -1.0 + 1e-15, 1.0 - 1e-15);
    const double yc = std::clamp(y, -0.99999, 0.99999);
    double w = -std::log((1.0 - yc) * (1.0 + yc)), p;
    if (w < 5.0) {
        w -= 2.5;
        p = 2.81022636e-08;
        p = 3.43273939e-07 + p * w;
        p = -3.5233877e-06 + p * w;
        p = -4.39150654e-06 + p * w;
        p = 0.00021858087 + p * w;
        p = -0.00125372503 + p * w;
        p = -0.00417768164 + p * w;
        p = 0.246640727 + p * w;
        p = 1.50140941 + p * w;
    } else {
        w = std::sqrt(w) - 3.0;
        p = -0.000200214257;
        p = 0.000100950558 + p * w;
        p = 0.00134934322 + p * w;
        p = -0.00367342844 + p * w;
        p = 0.00573950773 + p * w;
        p = -0.0076224613 + p * w;
        p = 0.00943887047 + p * w;
        p = 1.00167406 + p * w;
        p = 2.83297682 + p * w;
    }
    double x = p * yc;
    for (int i = 0; i < 8; ++i) {
        const double slope = 2.0 * kInvSqrtPi * std::exp(-x * x);
        if (slope <= 0.0) break;
        const double step = (std::erf(x) - y) / slope;
        x -= step;
        if (std::abs(step) < 1e-12 * (1.0 + std::abs(x))) break;
    }
    return x;
}

// Slopes of the Beckmann (alpha = 1) normals visible from a direction at
// cos(theta) = cosThetaI with azimuth 0 (Heitz & d'Eon 2014): the x slope by
// inverting its CDF, 1 + erf(x) + tan(theta) exp(-x^2) / sqrt(pi) up to
// normalisation, with safeguarded Newton steps in the erf domain (Jakob's scheme);
// the y slope is an independent unit Gaussian in the erf domain.
Imath::V2d beckmannSlopes(double cosThetaI, double u1, double u2) {
    const double sinThetaI = std::sqrt(std::max(0.0, 1.0 - cosThetaI * cosThetaI));
    if (sinThetaI < 1e-7) {  // normal incidence: the plain Beckmann slopes
        const double r = std::sqrt(-std::log(1.0 - u1)), phi = 2.0 * kPiD * u2;
        return {r * std::cos(phi), r * std::sin(phi)};
    }
    const double tanThetaI = sinThetaI / cosThetaI, cotThetaI = cosThetaI / sinThetaI;
    const double thetaI = std::acos(cosThetaI);
    const double target = std::max(u1, 1e-9);
    double lo = -1.0, hi = std::erf(cotThetaI);
    const double normalization = 1.0 / (1.0 + hi + kInvSqrtPi * tanThetaI * std::exp(-cotThetaI * cotThetaI));
    // Initial guess: a fitted inverse (Jakob), then Newton with bisection fallback.
    const double fit = 1.0 + thetaI * (-0.876 + thetaI * (0.4265 - 0.0594 * thetaI));
    double b = hi - (1.0 + hi) * std::pow(1.0 - target, fit);
    for (int it = 0; it < 40; ++it) {
        if (!(b > lo && b < hi)) b = 0.5 * (lo + hi);
        const double x = erfInv(b);
        const double value = normalization * (1.0 + b + kInvSqrtPi * tanThetaI * std::exp(-x * x)) - target;
        if (std::abs(value) < 1e-10) break;
        if (value > 0.0) hi = b; else lo = b;
        if (hi - lo < 1e-15) break;
        const double derivative = normalization * (1.0 - x * tanThetaI);
        b -= value / derivative;
    }
    return {erfInv(b), erfInv(2.0 * std::max(u2, 1e-9) - 1.0)};
}

// Smith's Lambda of the Beckmann distribution at a = cot(theta) / alpha.
double beckmannLambda(double a) {
    return std::max(0.0, 0.5 * (std::erf(a) - 1.0) + std::exp(-a * a) * kInvSqrtPi / (2.0 * a));
}

// Regularised incomplete beta function I_x(a, b) (continued fraction by
// Lentz's method, as in Numerical Recipes' betai); tgamma keeps it thread-safe
// (lgamma writes a global); fine for a + b < 170.
double incompleteBetaFraction(double a, double b, double x) {
    constexpr double kTiny = 1e-300;
    double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
    d = 1.0 / (std::abs(d) < kTiny ? kTiny : d);
    double h = d;
    for (int m = 1; m <= 300; ++m) {
        const int m2 = 2 * m;
        for (const double aa : {m * (b - m) * x / ((a - 1.0 + m2) * (a + m2)),
                                -(a + m) * (a + b + m) * x / ((a + m2) * (a + 1.0 + m2))}) {
            d = 1.0 + aa * d;
            d = 1.0 / (std::abs(d) < kTiny ? kTiny : d);
            c = 1.0 + aa / c;
            if (std::abs(c) < kTiny) c = kTiny;
            h *= d * c;
        }
        if (std::abs(d * c - 1.0) < 1e-13) break;
    }
    return h;
}

double incompleteBeta(double a, double b, double x) {
    if (x <= 0.0) return 0.0;
    if (x >= 1.0) return 1.0;
    const double front = std::tgamma(a + b) / (std::tgamma(a) * std::tgamma(b)) * std::pow(x, a) * std::pow(1.0 - x, b);
    if (x < (a + 1.0) / (a + b + 2.0)) return front * incompleteBetaFraction(a, b, x) / a;
    return 1.0 - front * incompleteBetaFraction(b, a, 1.0 - x) / b;
}

// Smith's Lambda of the isotropic Phong distribution (e + 2)/(2 pi) cos^e, at
// a = cot(theta), e <= 300. Its slope marginal is P2(x) = K (1 + x^2)^(-(e+3)/2)
// with K = (e+2) / (2 sqrt(pi)) Gamma((e+3)/2) / Gamma((e+4)/2), and
// Lambda = (1/a) integral_a^inf (x - a) P2(x) dx
//        = K (1 + a^2)^(-(e+1)/2) / ((e+1) a) - I_t(e/2 + 1, 1/2) / 2,  t = 1/(1 + a^2).
double phongLambda(double e, double a) {
    const double t = 1.0 / (1.0 + a * a);
    const double k = (e + 2.0) * 0.5 * kInvSqrtPi * std::tgamma(0.5 * (e + 3.0)) / std::tgamma(0.5 * (e + 4.0));
    const double tail = k * std::pow(t, 0.5 * (e + 1.0)) / ((e + 1.0) * a);
    return std::max(0.0, tail - 0.5 * incompleteBeta(0.5 * e + 1.0, 0.5, t));
}

}  // namespace

MicrofacetDistribution::MicrofacetDistribution(MicrofacetKind kind, float alphaU, float alphaV)
    : kind_(kind),
      alphaU_(std::clamp(std::isfinite(alphaU) ? alphaU : kMinAlpha, kMinAlpha, kMaxAlpha)),
      alphaV_(std::clamp(std::isfinite(alphaV) ? alphaV : kMinAlpha, kMinAlpha, kMaxAlpha)) {
    if (kind_ == MicrofacetKind::Phong) {
        // Exponent e = 2/alpha^2 - 2 >= 0 (Mitsuba 0.5); alpha > 1 means e = 0,
        // so alphas are capped at 1. Anisotropy stretches the slopes of the
        // isotropic distribution of the geometric-mean alpha.
        alphaU_ = std::min(alphaU_, 1.0f);
        alphaV_ = std::min(alphaV_, 1.0f);
        const float alpha = std::sqrt(alphaU_ * alphaV_);
        exponent_ = std::max(2.0f / (alpha * alpha) - 2.0f, 0.0f);
        stretchU_ = alphaU_ / alpha;
        stretchV_ = alphaV_ / alpha;
    }
}

float MicrofacetDistribution::D(const Vec3& m) const {
    if (m.z <= 0.0f) return 0.0f;
    const float x2 = m.x * m.x, y2 = m.y * m.y, z2 = m.z * m.z;
    switch (kind_) {
    case MicrofacetKind::Beckmann: {
        const float exponent = (x2 / (alphaU_ * alphaU_) + y2 / (alphaV_ * alphaV_)) / z2;
        if (!(exponent < 100.0f)) return 0.0f;  // underflow; also keeps 1/mz^4 finite
        return std::exp(-exponent) / (kPi * alphaU_ * alphaV_ * z2 * z2);
    }
    case MicrofacetKind::GGX: {
        const float d = x2 / (alphaU_ * alphaU_) + y2 / (alphaV_ * alphaV_) + z2;
        return 1.0f / (kPi * alphaU_ * alphaV_ * d * d);
    }
    case MicrofacetKind::Phong: {
        // Slope density (e+2)/(2 pi) (1 + r^2)^(-(e+4)/2) of the unstretched
        // slopes, over mz^4 and the stretch's Jacobian; in double so that
        // grazing normals neither overflow nor divide 0 by 0.
        const double mz = m.z, sx = m.x / (mz * stretchU_), sy = m.y / (mz * stretchV_);
        const double r2 = sx * sx + sy * sy;
        const double p22 = (exponent_ + 2.0) / (2.0 * kPiD) * std::pow(1.0 + r2, -0.5 * (exponent_ + 4.0));
        const double d = p22 / (double(stretchU_) * stretchV_ * mz * mz * mz * mz);
        return std::isfinite(d) ? float(std::min(d, 1e30)) : 0.0f;
    }
    }
    return 0.0f;
}

float MicrofacetDistribution::alphaTan2(const Vec3& v) const {
    const float z2 = v.z * v.z;
    const float num = v.x * v.x * alphaU_ * alphaU_ + v.y * v.y * alphaV_ * alphaV_;
    if (num <= 0.0f) return 0.0f;
    return z2 > 0.0f ? num / z2 : kInfinity;
}

float MicrofacetDistribution::lambda(const Vec3& v) const {
    const float t2 = alphaTan2(v);
    if (t2 <= 0.0f) return 0.0f;
    if (!std::isfinite(t2)) return kInfinity;
    switch (kind_) {
    case MicrofacetKind::Beckmann:
        return float(beckmannLambda(1.0 / std::sqrt(double(t2))));
    case MicrofacetKind::GGX:
        // (sqrt(1 + t2) - 1) / 2 without cancellation.
        return t2 / (2.0f * (std::sqrt(1.0f + t2) + 1.0f));
    case MicrofacetKind::Phong: {
        // Stretch-invariance: the isotropic Lambda at cot(theta) of the
        // unstretched direction, alpha / sqrt(t2). Beyond e = 300 Phong is
        // Beckmann with alpha^2 = 2 / (e + 2) to within 0.5%.
        const double cotTheta = std::sqrt(double(alphaU_) * alphaV_ / t2);
        if (exponent_ > 300.0f) return float(beckmannLambda(cotTheta * std::sqrt(0.5 * (exponent_ + 2.0))));
        return float(phongLambda(exponent_, cotTheta));
    }
    }
    return 0.0f;
}

float MicrofacetDistribution::G1(const Vec3& v, const Vec3& m) const {
    if (v.dot(m) * v.z <= 0.0f) return 0.0f;
    return 1.0f / (1.0f + lambda(v));
}

float MicrofacetDistribution::G(const Vec3& wo, const Vec3& wi, const Vec3& m) const {
    if (wo.dot(m) * wo.z <= 0.0f || wi.dot(m) * wi.z <= 0.0f) return 0.0f;
    return 1.0f / (1.0f + lambda(wo) + lambda(wi));
}

float MicrofacetDistribution::G(const Vec3& wo, const Vec3& wi, const Vec3& m, float lambdaWo) const {
    if (wo.dot(m) * wo.z <= 0.0f || wi.dot(m) * wi.z <= 0.0f) return 0.0f;
    return 1.0f / (1.0f + lambdaWo + lambda(wi));
}

Vec3 MicrofacetDistribution::sample(const Vec3& wo, const Vec2& u) const {
    return kind_ == MicrofacetKind::Phong ? samplePhong(u) : sampleVisible(wo, u);
}

float MicrofacetDistribution::pdf(const Vec3& wo, const Vec3& m) const {
    if (m.z <= 0.0f) return 0.0f;
    if (kind_ == MicrofacetKind::Phong) return D(m) * m.z;
    if (wo.z <= 0.0f) return 0.0f;
    const float pdf = G1(wo, m) * std::max(0.0f, wo.dot(m)) * D(m) / wo.z;
    return std::isfinite(pdf) ? pdf : 0.0f;
}

Vec3 MicrofacetDistribution::sampleVisible(const Vec3& wo, const Vec2& u) const {
    // Stretch to the alpha = 1 configuration.
    const Imath::V3d v = Imath::V3d(double(alphaU_) * wo.x, double(alphaV_) * wo.y, std::max(double(wo.z), 1e-30))
                             .normalized();
    if (kind_ == MicrofacetKind::GGX) {
        // Heitz 2018: a uniform point on the projected hemisphere seen from v.
        const double lensq = v.x * v.x + v.y * v.y;
        const Imath::V3d t1 = lensq > 0.0 ? Imath::V3d(-v.y, v.x, 0.0) / std::sqrt(lensq) : Imath::V3d(1, 0, 0);
        const Imath::V3d t2 = v.cross(t1);
        const double r = std::sqrt(double(u.x)), phi = 2.0 * kPiD * u.y;
        const double p1 = r * std::cos(phi);
        const double s = 0.5 * (1.0 + v.z);
        const double p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * r * std::sin(phi);
        const Imath::V3d nh = t1 * p1 + t2 * p2 + v * std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2));
        const Imath::V3d m = Imath::V3d(alphaU_ * nh.x, alphaV_ * nh.y, std::max(1e-30, nh.z)).normalized();
        return Vec3(float(m.x), float(m.y), float(m.z));
    }
    // Beckmann: sample slopes for azimuth 0, rotate to v's azimuth, unstretch.
    Imath::V2d slope = beckmannSlopes(v.z, u.x, u.y);
    const double sinTheta = std::sqrt(v.x * v.x + v.y * v.y);
    const double cosPhi = sinTheta > 0.0 ? v.x / sinTheta : 1.0, sinPhi = sinTheta > 0.0 ? v.y / sinTheta : 0.0;
    slope = Imath::V2d(cosPhi * slope.x - sinPhi * slope.y, sinPhi * slope.x + cosPhi * slope.y);
    const Imath::V3d m = Imath::V3d(-slope.x * alphaU_, -slope.y * alphaV_, 1.0).normalized();
    return Vec3(float(m.x), float(m.y), float(m.z));
}

Vec3 MicrofacetDistribution::samplePhong(const Vec2& u) const {
    // Isotropic D(m) mz: cos(theta) = (1 - u)^(1/(e+2)), uniform azimuth; then
    // the slopes are stretched, which maps D mz dm of one onto the other.
    const double cosTheta = std::pow(1.0 - double(u.x), 1.0 / (exponent_ + 2.0));
    const double tanTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta)) / cosTheta;
    const double phi = 2.0 * kPiD * u.y;
    const Imath::V3d m =
        Imath::V3d(tanTheta * std::cos(phi) * stretchU_, tanTheta * std::sin(phi) * stretchV_, 1.0).normalized();
    return Vec3(float(m.x), float(m.y), float(m.z));
}

}  // namespace vrl
