// MicrofacetDistribution: the normal distributions D(m) of the rough models
// (Walter et al. 2007, "Microfacet Models for Refraction through Rough
// Surfaces") in the local shading frame (+z = macro-surface normal), with
// anisotropic roughness alphaU (along local x) and alphaV (along local y):
//   Beckmann  D = exp(-(mx^2/au^2 + my^2/av^2) / mz^2) / (pi au av mz^4)
//   GGX       D = 1 / (pi au av (mx^2/au^2 + my^2/av^2 + mz^2)^2)
//   Phong     (e+2)/(2 pi) mz^e with e = 2/alpha^2 - 2 (Mitsuba 0.5's mapping);
//             anisotropic: that of alpha = sqrt(au av) with its slopes stretched
//             by (au, av) / alpha (not Mitsuba's Ashikhmin-Shirley form, whose
//             Smith masking has no closed form).
// Every D is normalised: integral of D(m) mz dm = 1. Masking is Smith's, with
// the exact Lambda of each distribution (Phong: via the incomplete beta
// function; Beckmann's for e > 300); G(wo, wi) is the height-correlated form
// 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014).
// Sampling: Beckmann and GGX draw the normals visible from wo (Heitz & d'Eon
// 2014; Heitz 2018) with pdf G1(wo) max(0, wo.m) D(m) / wo.z; Phong draws
// D(m) mz. sample() and pdf() describe the same density.
// Alphas are clamped to [1e-4, 10] so that every value stays finite.
#pragma once

#include "render/core/geometry.h"
#include "render/description/scene_description.h"

namespace vrl {

class MicrofacetDistribution {
public:
    static constexpr float kMinAlpha = 1e-4f;
    static constexpr float kMaxAlpha = 10.0f;

    MicrofacetDistribution(MicrofacetKind kind, float alphaU, float alphaV);

    // Density of microfacet normals per solid angle (0 for m.z <= 0).
    float D(const Vec3& m) const;
    // Smith's Lambda for direction v (|v.z| is used: symmetric about the surface).
    float lambda(const Vec3& v) const;
    // Smith masking of v by microfacets with normal m: 0 unless v.m and v.z agree in sign.
    float G1(const Vec3& v, const Vec3& m) const;
    // Height-correlated masking-shadowing of wo and wi seen through m.
    float G(const Vec3& wo, const Vec3& wi, const Vec3& m) const;
    // The same with lambda(wo) given (prepared once for many wi): bit for bit G(wo, wi, m).
    float G(const Vec3& wo, const Vec3& wi, const Vec3& m, float lambdaWo) const;

    // A microfacet normal (m.z > 0) for a view direction with wo.z > 0.
    Vec3 sample(const Vec3& wo, const Vec2& u) const;
    // Density of sample(wo, .) per solid angle of m; wo.z > 0.
    float pdf(const Vec3& wo, const Vec3& m) const;

    MicrofacetKind kind() const { return kind_; }
    float alphaU() const { return alphaU_; }
    float alphaV() const { return alphaV_; }

private:
    // alpha^2 tan^2(theta) of direction v along its azimuth (anisotropic projection).
    float alphaTan2(const Vec3& v) const;
    Vec3 sampleVisible(const Vec3& wo, const Vec2& u) const;
    Vec3 samplePhong(const Vec2& u) const;

    MicrofacetKind kind_;
    float alphaU_, alphaV_;
    float exponent_ = 0.0f, stretchU_ = 1.0f, stretchV_ = 1.0f;  // Phong
};

}  // namespace vrl
