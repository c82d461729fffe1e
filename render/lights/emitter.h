// render/lights/: light sources (point, spot, area) and how they are sampled,
// for next-event estimation on camera paths and emission on light paths.
//
// Emitter: a light source. Point (isotropic intensity, W/sr), Spot (Mitsuba's
// linear angular falloff between beamWidth and cutoffAngle, along local +z) and
// Area (uniform radiance from the front side of a triangle mesh).
// Two sampling routines: sampleDirect for next-event estimation from a point,
// sampleEmission for light tracing (a ray leaving the light, weighted by flux).
// pdfDirect gives sampleDirect's density for a point found another way (a BSDF-
// sampled ray that hit the light), so the two strategies can be weighted by
// multiple importance sampling (Veach 1997 §9.2); point and spot lights are Dirac
// (density 0 there: no other strategy finds them).
#pragma once

#include "render/core/geometry.h"
#include "render/core/rgb.h"
#include "render/core/transform.h"
#include "render/core/triangle_mesh.h"

#include <memory>
#include <vector>

namespace vrl {

// A point on an emitter seen from a reference point.
struct DirectLightSample {
    Vec3 position{0.0f};   // on the light
    Vec3 direction{0.0f};  // unit, from the reference point to `position`
    float distance = 0; // |position - reference|
    Rgb weight{0.0f};   // incident radiance / pdf (solid angle), excluding transmittance and visibility
    float pdf = 0.0f;   // that solid-angle pdf (= pdfDirect); 0 for a Dirac emitter (point, spot)
};

// A ray leaving an emitter for light tracing.
struct EmissionSample {
    Ray ray;
    Rgb weight{0.0f};  // flux carried by this sample: Le cos / (pdf_area pdf_dir), or I / pdf_dir
};

class Emitter {
public:
    virtual ~Emitter() = default;
    // Total emitted flux (W), used to choose emitters in proportion to power.
    virtual Rgb power() const = 0;
    virtual DirectLightSample sampleDirect(const Vec3& reference, const Vec2& u) const = 0;
    virtual EmissionSample sampleEmission(const Vec2& uPosition, const Vec2& uDirection) const = 0;
    // Solid-angle density (1/sr) with which sampleDirect(reference, .) picks `position`, a
    // point of the emitter with geometric normal `normal`: pdf_area d^2 / |cos| (+infinity
    // at grazing incidence, 0 where reference = position). 0 for Dirac emitters.
    virtual float pdfDirect(const Vec3& /*reference*/, const Vec3& /*position*/, const Vec3& /*normal*/) const {
        return 0.0f;
    }
    // Radiance leaving an area emitter at a point with geometric normal n towards dirOut.
    virtual Rgb emittedRadiance(const Vec3& /*normal*/, const Vec3& /*dirOut*/) const { return Rgb(0.0f); }
    // The medium the emitter sits in (-1 = vacuum/unknown), for light tracing.
    int medium = -1;
};

std::unique_ptr<Emitter> makePointEmitter(const Vec3& position, const Rgb& intensity);
// cutoff/beamWidth in degrees; worldFromLight maps local +z to the spot axis.
std::unique_ptr<Emitter> makeSpotEmitter(const Transform& worldFromLight, const Rgb& intensity, float cutoffDegrees,
                                         float beamWidthDegrees);
// `mesh` must outlive the emitter (the scene owns both).
std::unique_ptr<Emitter> makeAreaEmitter(const TriangleMesh& mesh, const Rgb& radiance);

// Picks emitters in proportion to luminance of their power.
class EmitterSampler {
public:
    explicit EmitterSampler(const std::vector<const Emitter*>& emitters);
    bool empty() const { return cdf_.empty(); }
    // Returns the index and its selection probability.
    std::pair<size_t, float> sample(float u) const;
    float probability(size_t index) const { return probabilities_[index]; }

private:
    std::vector<float> cdf_, probabilities_;
};

}  // namespace vrl
