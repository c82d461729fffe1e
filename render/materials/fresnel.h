// Fresnel reflectance of smooth interfaces (unpolarised light; Born & Wolf):
// dielectric-dielectric with total internal reflection, dielectric-conductor
// for a complex relative index eta + ik per RGB channel, and the diffuse
// (hemispherical, cosine-weighted) Fresnel reflectance Fdr used by the plastic
// models. Cosines are taken against the interface normal; eta is the relative
// index interior / exterior, the interior lying behind the normal.
#pragma once

#include "render/core/rgb.h"

#include <algorithm>
#include <cmath>

namespace vrl {

struct DielectricFresnel {
    float reflectance = 1.0f;  // F in [0, 1]; 1 on total internal reflection
    // Cosine of the refracted direction with the normal, of the opposite sign to
    // cosThetaI (it lies on the other side); 0 on total internal reflection.
    float cosThetaT = 0.0f;
};

// cosThetaI > 0: the incident direction is on the exterior (normal) side.
// Inline: microfacet BSDFs call it once or twice per evaluation, and a cut's
// glossy bounds evaluate them at ten points per node.
inline DielectricFresnel fresnelDielectric(float cosThetaI, float eta) {
    if (eta == 1.0f) return {0.0f, -cosThetaI};
    // Snell: sin_t = sin_i / eta entering, sin_i * eta leaving.
    const float scale = cosThetaI > 0.0f ? 1.0f / eta : eta;
    const float cosI = std::min(std::abs(cosThetaI), 1.0f);
    const float cosTSqr = 1.0f - (1.0f - cosI * cosI) * (scale * scale);
    if (cosTSqr <= 0.0f) return {1.0f, 0.0f};  // total internal reflection
    const float cosT = std::sqrt(cosTSqr);
    // Relative index seen from the incident side.
    const float n = cosThetaI > 0.0f ? eta : 1.0f / eta;
    const float rs = (cosI - n * cosT) / (cosI + n * cosT);
    const float rp = (n * cosI - cosT) / (n * cosI + cosT);
    const float f = std::clamp(0.5f * (rs * rs + rp * rp), 0.0f, 1.0f);
    return {f, cosThetaI > 0.0f ? -cosT : cosT};
}

// Conductor reflectance for |cosThetaI| with the complex relative index eta + ik
// (exact formula, e.g. Mitsuba's fresnelConductorExact). At normal incidence it
// is ((eta-1)^2 + k^2) / ((eta+1)^2 + k^2).
Rgb fresnelConductor(float cosThetaI, const Rgb& eta, const Rgb& k);

// Fdr(eta) = 2 * integral_0^1 F(mu, eta) mu dmu: the reflectance of a
// dielectric boundary to uniform (cosine-weighted) incident light arriving from
// the side where the relative index of the other side is eta (Mitsuba's
// fresnelDiffuseReflectance). For eta > 1 the integrand is smooth and is
// integrated numerically (Simpson, 256 intervals, error < 1e-6; the usual fits,
// Egan & Hilgeman 1973 or d'Eon & Irving 2011, are off by up to 1% for large
// eta); for eta < 1 the exact reciprocity relation
// 1 - Fdr(eta) = eta^2 (1 - Fdr(1/eta)) accounts for total internal reflection.
// Meant for set-up time (about 260 evaluations of F).
float fresnelDiffuseReflectance(float eta);

}  // namespace vrl
