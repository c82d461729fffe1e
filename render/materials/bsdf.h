// render/materials/: how surfaces scatter light: BSDFs, microfacet distributions,
// Fresnel terms and bitmap textures.
//
// Bsdf: the surface models of the scene subset (BsdfDescription lists them with
// their Mitsuba parameters). Directions are world-space unit vectors pointing
// away from the surface: wo towards the previous path vertex (the viewer on a
// camera path, the light on a light path), wi towards the next one.
//
// Sidedness follows Mitsuba: the front is the side the geometric normal points
// to. One-sided models (all but dielectric/roughdielectric and twosided ones) are
// black when wo is behind. Reflection needs wo and wi on the same geometric side,
// transmission on opposite sides (no light leaks through shading normals).
//
// eval returns f(wo, wi) |cos(wi, n_s)| for the non-Dirac lobes only (zero for
// a purely specular model); sample may pick a Dirac lobe (BsdfSample::delta) and
// then returns its weight directly. In Importance mode (light paths) the
// adjoint corrections apply: no 1/eta^2 radiance scaling on refraction, and the
// shading-normal factor |wo.n_s||wi.n_g| / (|wo.n_g||wi.n_s|) (Veach 1997 §5.3).
#pragma once

#include "render/core/geometry.h"
#include "render/core/rgb.h"
#include "render/materials/texture.h"
#include "render/description/scene_description.h"

#include <optional>
#include <span>

namespace vrl {

enum class TransportMode { Radiance, Importance };

// The surface point as a BSDF sees it.
struct ShadingPoint {
    Vec3 geometricNormal;  // unit, the shape's front side
    Vec3 shadingNormal;    // unit, in the same hemisphere as geometricNormal
    Vec2 uv{0.0f, 0.0f};
};

struct BsdfSample {
    Vec3 wi;
    Rgb weight{0.0f};    // f |cos(wi, n_s)| / pdf (with the Importance-mode corrections)
    float pdf = 0.0f;    // solid-angle pdf; for a Dirac lobe, the probability of picking it
    bool delta = false;  // a Dirac (specular) lobe was sampled
};

class Bsdf;

// The model-independent part of a query: the shading frame and wo in it.
struct BsdfSetup {
    Frame frame;        // shading frame, flipped to wo's side for two-sided models
    Vec3 ng;            // geometric normal, flipped likewise
    Vec3 woLocal;
    float cosWoGeometric = 0.0f;  // wo . ng, non-zero
};

// What a model's eval reads besides wo and wi: its textures at uv (those it uses)
// and, for plastics, the Fresnel reflectance at wo.
struct BsdfLookups {
    Rgb diffuse{0.0f};   // reflectance (diffuse, ward) or the plastic base (plasticDiffuse)
    Rgb specular{0.0f};  // specular reflectance (rough plastic, rough conductor, ward, rough dielectric)
    Rgb transmission{0.0f};  // specular transmittance (rough dielectric)
    float fresnelWo = 0.0f;  // plastics: F(wo.z)
    float lambdaWo = 0.0f;   // microfacet models: Smith's Lambda(wo), shared by every wi
};

// A BSDF at one point for one wo, with everything that depends on them alone
// (setup, textures, F(wo)) done once: eval(wi, mode) == Bsdf::eval(sp, wo, wi, mode)
// bit for bit (Bsdf::eval is prepare + eval). For callers that evaluate one
// point against many wi: VRL-lit surfaces, a cut's bounds.
class PreparedBsdf {
public:
    PreparedBsdf() = default;  // black for every wi
    Rgb eval(const Vec3& wi, TransportMode mode) const;
    // Bsdf::lambertianBound at the prepared point, from the lookups (no texture
    // read): a bound on eval(wi) / |cos| over every wi. 0 where nothing was
    // prepared (eval is black for every wi); empty for non-Lambertian models.
    std::optional<Rgb> lambertianBound() const;
    // A proven bound on eval(wi, Radiance) over every unit wi within `halfAngle`
    // (radians, >= pi: every direction) of the unit world-space `axis`: the largest
    // f |cos| a receiver can show towards a light cluster seen under that cone.
    // For diffuse and smooth plastic, and for rough plastic and rough conductor
    // with a Beckmann or GGX distribution where wo lies above the shading horizon
    // (Bsdf::hasConeBound); empty elsewhere (Phong, Ward, rough dielectric, wo at or
    // below the shading horizon). 0 where nothing was prepared.
    //
    // Derivation (local shading frame, n = +z; the models of evalLocal). Let c be
    // the axis and beta the half-angle; every wi in the cone has
    //   theta_i >= theta_c - beta  (theta: the angle to n),
    //   gamma = angle(wo, wi) <= gamma_max = angle(wo, c) + beta.
    // Cosine terms: wi.z <= cos(max(0, theta_c - beta)) = cosMax.
    // Half vector h = (wo + wi) / |wo + wi|. Along the great-circle arc from c to
    // wi (inside the cone) with unit speed, d(wo + wi) has length 1 and
    // normalising divides its tangential part by |wo + wi| = 2 cos(gamma / 2), so
    //   angle(h, h_c) <= beta / (2 cos(gamma_max / 2)) = beta_h   (gamma_max < pi),
    // and theta_h lies in [theta_hc - beta_h, theta_hc + beta_h] clamped to [0, pi/2]
    // (D = 0 below the horizon): the range taken for small cones (beta_h < 1e-3).
    // Wider cones: wi -> h is a diffeomorphism of the sphere less -wo onto the
    // hemisphere around wo, and theta_h has one critical point there, its minimum 0
    // at wo's mirror direction r; so over the cap theta_h takes its extremes on the
    // boundary circle (its minimum is 0 where the cap holds r). Twelve points spread
    // evenly on the circle give them up to pi/12 x sin(beta) x beta_h / beta (the
    // circle's length per radian, times the Lipschitz factor above). Both ranges are
    // widened by 1e-6 for eval's float half vector, where a narrow lobe is steep.
    // With gamma_max >= pi every h is possible.
    // D: with x^2 + y^2 = sin^2 theta_h and alpha_max = max(alpha_u, alpha_v),
    //   x^2/au^2 + y^2/av^2 >= sin^2 theta_h / alpha_max^2, so
    //   GGX       D <= 1 / (pi au av (cos^2 + sin^2 / alpha_max^2)^2): the base is linear
    //             in sin^2, so the largest value is at an end of the theta_h range;
    //   Beckmann  D <= e^(-t / alpha_max^2) (1 + t)^2 / (pi au av), t = tan^2 theta_h,
    //             largest at t* = 2 alpha_max^2 - 1 where t* is in range, else at an end.
    // G <= 1 / (1 + Lambda(wo)) (Smith's height-correlated G = 1 / (1 + Lambda_o + Lambda_i)
    // or 0, Lambda >= 0).
    // Fresnel: the plastic's F(cos phi), phi = angle(wo, h) = gamma / 2. Two limits:
    // phi <= gamma_max / 2, and, by the triangle inequality on the sphere,
    // phi <= angle(wo, n) + angle(n, h) = theta_o + theta_h. For eta > 1 the unpolarised
    // reflectance has no interior maximum in the angle (it rises, or for eta above about
    // 3.5 dips below F(0) first; bsdf_test checks both on a fine grid up to eta 40), so
    // over [0, phi] F <= F^(phi) = max(F(0), F(phi)). Coupled with D: split the theta_h
    // range into pieces [t0, t1] (6 at most, widths doubling from alpha_max / 2, the last
    // one reaching theta_h's top); on each, D <= D_max(t0, t1) and
    // F <= F^(min(gamma_max / 2, theta_o + t1)), so
    //   F D <= max over the pieces of D_max(t0, t1) F^(min(gamma_max / 2, theta_o + t1))
    // (phi widened by 1e-6 for eval's float half vector, as theta_h above).
    // (F at gamma_max / 2 alone is far larger for a wide cone holding the mirror
    // direction, where D peaks at theta_h = 0 and F there is near F(theta_o); bsdf_test
    // checks that the coupled bound stays within a small factor of the largest value
    // found for such cones.)
    // For eta <= 1, F <= 1. The conductor's F <= 1.
    // So, with k_s the specular reflectance and wo.z > 0 fixed,
    //   rough conductor  f |cos| = k_s F D G / (4 wo.z) <= k_s D_max G_max / (4 wo.z);
    //   rough plastic    f |cos| <= k_s (F D)_max G_max / (4 wo.z)
    //                              + rho (1 - F(wo)) cosMax / (pi eta^2)   (1 - F(wi) <= 1).
    // Float evaluation of those terms is covered by a 1.0001 factor (relative
    // errors of a few float steps); rounding of the caller's directions belongs in beta.
    std::optional<Rgb> coneBound(const Vec3& axis, double halfAngle) const;
    // Replaces the texture lookups with their mean over `uvs`, keeping this point's
    // geometry (frame, wo): eval is linear in the lookups, so eval(wi) becomes the mean
    // of the evaluations at those texture coordinates, and the bounds above follow it
    // (they read the same lookups). For a point shaded once for a whole pixel, whose
    // texture would otherwise be sampled at one place (pixel_footprint.h). No effect
    // where nothing was prepared, on models without textures, or for empty `uvs`.
    void averageTexturesOver(std::span<const Vec2> uvs);

private:
    friend class Bsdf;
    const Bsdf* bsdf_ = nullptr;  // null: wo is grazing, behind a one-sided model, or the model has no non-Dirac lobe
    BsdfSetup setup_;
    BsdfLookups lookups_;
};

class Bsdf {
public:
    // The default is Mitsuba's default material: diffuse, reflectance 0.5, one-sided.
    Bsdf() = default;
    // textures[i] is the loaded SceneDescription::textures[i] (a ColorDescription's index).
    Bsdf(const BsdfDescription& description, std::span<const std::shared_ptr<const Texture>> textures);
    static Bsdf null();

    BsdfDescription::Kind kind() const { return kind_; }
    bool isNull() const { return kind_ == BsdfDescription::Kind::Null; }
    // Every lobe is a Dirac (dielectric, conductor): eval is always zero.
    bool isPurelySpecular() const;
    // Some lobe is a Dirac (dielectric, conductor, plastic): paths must count
    // emission found after sampling it.
    bool hasSpecular() const;
    bool twoSided() const { return twoSided_; }
    // Some colour parameter is a texture (its lookups depend on uv).
    bool isTextured() const;

    Rgb eval(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi, TransportMode mode) const;
    PreparedBsdf prepare(const ShadingPoint& sp, const Vec3& wo) const;
    float pdf(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi) const;
    // u: two uniforms for the direction, uLobe: one for the choice of lobe.
    std::optional<BsdfSample> sample(const ShadingPoint& sp, const Vec3& wo, const Vec2& u, float uLobe,
                                     TransportMode mode) const;
    // A bound on f(wo, wi) (without the cosine) over every wi, for models whose
    // non-Dirac part is Lambertian: diffuse (rho/pi, exact) and smooth plastic
    // (its diffuse base through the coating, (1 - F) <= 1). Empty for the others
    // (glossy lobes, purely specular and null models).
    std::optional<Rgb> lambertianBound(const Vec2& uv) const;
    // Whether PreparedBsdf::coneBound is proven for this model (wherever wo lies above
    // the shading horizon): Lambertian-bounded models, and rough plastic and rough
    // conductor with a Beckmann or GGX distribution.
    bool hasConeBound() const;
    // The glossy lobe's roughness: the smaller of alpha_u and alpha_v for the rough
    // (microfacet) models and Ward; 0 for models without a glossy lobe.
    float glossyRoughness() const;
    // Hemispherical reflectance estimate (for previews and light-tree weights): the
    // diffuse colour, or the specular colour for metals and glass.
    Rgb albedo(const Vec2& uv) const;

private:
    // Local-frame models (bsdf.cpp): wo, wi in the shading frame, already checked
    // against the geometric sides (both z > 0 for the reflection models).
    Rgb evalLocal(const Vec3& wo, const Vec3& wi, const BsdfLookups& lookups, TransportMode mode) const;
    BsdfLookups lookups(const Vec2& uv, const Vec3& woLocal) const;
    float pdfLocal(const Vec3& wo, const Vec3& wi) const;
    // Plastic models: diffuse base colour with the internal-reflection term, and the
    // probability of sampling the specular lobe for wo.z = cosThetaO.
    Rgb plasticDiffuse(const Vec2& uv) const;
    float plasticSpecularProbability(float cosThetaO) const;
    // lambertianBound from the model's diffuse lookup (BsdfLookups::diffuse).
    std::optional<Rgb> lambertianBoundOf(const Rgb& diffuse) const;
    bool transmits() const;
    friend class PreparedBsdf;

    BsdfDescription::Kind kind_ = BsdfDescription::Kind::Diffuse;
    TexturedColor reflectance_{Rgb(0.5f), nullptr};
    TexturedColor specularReflectance_{Rgb(1.0f), nullptr};
    TexturedColor specularTransmittance_{Rgb(1.0f), nullptr};
    float eta_ = 1.5046f / 1.000277f;  // interior / exterior index (dielectric, plastic)
    Rgb conductorEta_{1.0f}, conductorK_{0.0f};  // relative to the exterior
    MicrofacetKind distribution_ = MicrofacetKind::Beckmann;
    float alphaU_ = 0.1f, alphaV_ = 0.1f;
    bool nonlinear_ = false;
    BsdfDescription::WardVariant wardVariant_ = BsdfDescription::WardVariant::Balanced;
    bool twoSided_ = false;
    // Plastic: diffuse Fresnel reflectance inside (Fdr) and the specular sampling weight.
    float fdrInternal_ = 0.0f, fdrExternal_ = 0.0f;
    float specularSamplingWeight_ = 0.5f;
};

}  // namespace vrl
