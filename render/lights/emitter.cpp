#include "render/lights/emitter.h"

#include "render/core/sampling.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace vrl {

namespace {

class PointEmitter final : public Emitter {
public:
    PointEmitter(const Vec3& position, const Rgb& intensity) : position_(position), intensity_(intensity) {}
    Rgb power() const override { return intensity_ * (4.0f * kPi); }
    DirectLightSample sampleDirect(const Vec3& reference, const Vec2&) const override {
        const Vec3 d = position_ - reference;
        const float dist = d.length();
        if (dist <= 0.0f) return {};
        return {position_, d / dist, dist, intensity_ / (dist * dist)};
    }
    EmissionSample sampleEmission(const Vec2&, const Vec2& u) const override {
        return {Ray{position_, uniformSphere(u)}, intensity_ * (4.0f * kPi)};
    }

private:
    Vec3 position_;
    Rgb intensity_;
};

class SpotEmitter final : public Emitter {
public:
    SpotEmitter(const Transform& worldFromLight, const Rgb& intensity, float cutoffDegrees, float beamDegrees)
        : position_(worldFromLight.applyPoint(Vec3(0.0f))),
          axis_(worldFromLight.applyVector(Vec3(0, 0, 1)).normalized()),
          intensity_(intensity),
          cutoff_(cutoffDegrees * kPi / 180.0f),
          beam_(std::min(beamDegrees, cutoffDegrees) * kPi / 180.0f),
          cosCutoff_(std::cos(cutoff_)) {}

    // Mitsuba's spot falloff: 1 inside the beam, linear in angle down to 0 at the cutoff.
    float falloff(float cosTheta) const {
        if (cosTheta <= cosCutoff_) return 0.0f;
        const float theta = std::acos(std::min(1.0f, cosTheta));
        if (theta <= beam_ || cutoff_ <= beam_) return 1.0f;  // beam >= cutoff: a hard cone
        return (cutoff_ - theta) / (cutoff_ - beam_);
    }
    Rgb power() const override {
        // 2 pi * integral of falloff(theta) sin(theta) over [0, cutoff]; the linear
        // ramp (c - theta)/(c - b) integrates in closed form to
        // 1 - (sin c - sin b)/(c - b) for the plateau and ramp together.
        const double b = beam_, c = cutoff_;
        const double integral = c - b > 1e-6 ? 1.0 - (std::sin(c) - std::sin(b)) / (c - b) : 1.0 - std::cos(c);
        return intensity_ * float(2.0 * M_PI * integral);
    }
    DirectLightSample sampleDirect(const Vec3& reference, const Vec2&) const override {
        const Vec3 d = position_ - reference;
        const float dist = d.length();
        if (dist <= 0.0f) return {};
        const Vec3 dir = d / dist;
        const float f = falloff(-dir.dot(axis_));
        return {position_, dir, dist, intensity_ * (f / (dist * dist))};
    }
    EmissionSample sampleEmission(const Vec2&, const Vec2& u) const override {
        // Uniform in the cone of the cutoff angle.
        const float cosTheta = 1.0f - u.x * (1.0f - cosCutoff_);
        const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
        const Vec3 dir = Frame::fromNormal(axis_).toWorld(sphericalDirection(sinTheta, cosTheta, 2.0f * kPi * u.y));
        const float pdf = 1.0f / (2.0f * kPi * (1.0f - cosCutoff_));
        return {Ray{position_, dir.normalized()}, intensity_ * (falloff(cosTheta) / pdf)};
    }

private:
    Vec3 position_, axis_;
    Rgb intensity_;
    float cutoff_, beam_, cosCutoff_;
};

class AreaEmitter final : public Emitter {
public:
    AreaEmitter(const TriangleMesh& mesh, const Rgb& radiance) : mesh_(mesh), radiance_(radiance) {
        cdf_.reserve(mesh.triangles.size());
        double total = 0.0;
        for (size_t i = 0; i < mesh.triangles.size(); ++i) {
            total += mesh.triangleArea(i);
            cdf_.push_back(float(total));
        }
        area_ = float(total);
    }
    Rgb power() const override { return radiance_ * (kPi * area_); }
    Rgb emittedRadiance(const Vec3& normal, const Vec3& dirOut) const override {
        return normal.dot(dirOut) > 0.0f ? radiance_ : Rgb(0.0f);
    }
    DirectLightSample sampleDirect(const Vec3& reference, const Vec2& u) const override {
        const auto [p, n] = samplePoint(u);
        const Vec3 d = p - reference;
        const float dist2 = d.length2();
        if (!(dist2 > 0.0f)) return {};
        const float dist = std::sqrt(dist2);
        const Vec3 dir = d / dist;
        const float cosLight = -dir.dot(n);
        if (cosLight <= 0.0f) return {p, dir, dist, Rgb(0.0f), solidAnglePdf(dist2, cosLight)};
        // pdf_area = 1/area, so weight = L / pdf = L cos area / d^2.
        return {p, dir, dist, radiance_ * (cosLight * area_ / dist2), solidAnglePdf(dist2, cosLight)};
    }
    float pdfDirect(const Vec3& reference, const Vec3& position, const Vec3& normal) const override {
        const Vec3 d = position - reference;
        const float dist2 = d.length2();
        if (!(dist2 > 0.0f)) return 0.0f;
        return solidAnglePdf(dist2, d.dot(normal) / std::sqrt(dist2));
    }
    EmissionSample sampleEmission(const Vec2& uPosition, const Vec2& uDirection) const override {
        const auto [p, n] = samplePoint(uPosition);
        // Cosine-weighted hemisphere around n: weight = Le cos / (cos/pi * 1/area).
        return {Ray{p, Frame::fromNormal(n).toWorld(cosineHemisphere(uDirection)).normalized()}, radiance_ * (kPi * area_)};
    }

private:
    // Uniform in area (1/area) converted to solid angle at distance^2 dist2 and cosine
    // cosLight; +infinity at grazing incidence (MIS then gives that rare point to NEE alone).
    float solidAnglePdf(float dist2, float cosLight) const { return dist2 / (std::abs(cosLight) * area_); }
    std::pair<Vec3, Vec3> samplePoint(const Vec2& u) const {
        const float target = u.x * area_;
        const size_t i = std::min(size_t(std::upper_bound(cdf_.begin(), cdf_.end(), target) - cdf_.begin()),
                                  cdf_.size() - 1);
        const float lo = i == 0 ? 0.0f : cdf_[i - 1];
        const float span = cdf_[i] - lo;
        // Reuse the remainder of u.x as a fresh uniform for the triangle.
        const float u0 = span > 0.0f ? std::clamp((target - lo) / span, 0.0f, 1.0f) : 0.5f;
        const float su = std::sqrt(u0);
        const float b1 = 1.0f - su, b2 = u.y * su;
        const auto& t = mesh_.triangles[i];
        const Vec3 p = mesh_.positions[t[0]] * (1.0f - b1 - b2) + mesh_.positions[t[1]] * b1 + mesh_.positions[t[2]] * b2;
        return {p, mesh_.geometricNormal(i)};
    }

    const TriangleMesh& mesh_;
    Rgb radiance_;
    std::vector<float> cdf_;
    float area_ = 0.0f;
};

}  // namespace

std::unique_ptr<Emitter> makePointEmitter(const Vec3& position, const Rgb& intensity) {
    return std::make_unique<PointEmitter>(position, intensity);
}
std::unique_ptr<Emitter> makeSpotEmitter(const Transform& worldFromLight, const Rgb& intensity, float cutoffDegrees,
                                         float beamWidthDegrees) {
    return std::make_unique<SpotEmitter>(worldFromLight, intensity, cutoffDegrees, beamWidthDegrees);
}
std::unique_ptr<Emitter> makeAreaEmitter(const TriangleMesh& mesh, const Rgb& radiance) {
    return std::make_unique<AreaEmitter>(mesh, radiance);
}

EmitterSampler::EmitterSampler(const std::vector<const Emitter*>& emitters) {
    double total = 0.0;
    std::vector<double> weights;
    for (const auto* e : emitters) {
        weights.push_back(std::max(0.0f, luminance(e->power())));
        total += weights.back();
    }
    if (emitters.empty()) return;
    // All-black lights: choose uniformly so the estimator stays defined.
    double running = 0.0;
    for (double w : weights) {
        const double p = total > 0.0 ? w / total : 1.0 / double(weights.size());
        probabilities_.push_back(float(p));
        running += p;
        cdf_.push_back(float(running));
    }
    cdf_.back() = 1.0f;
}

std::pair<size_t, float> EmitterSampler::sample(float u) const {
    size_t i = size_t(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin());
    i = std::min(i, cdf_.size() - 1);
    while (probabilities_[i] == 0.0f && i + 1 < cdf_.size()) ++i;  // skip zero-power entries
    return {i, probabilities_[i]};
}

}  // namespace vrl
