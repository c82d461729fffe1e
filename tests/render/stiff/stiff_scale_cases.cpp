// Stiff cases, group "scale" (stiff_cases.h): the same scene with distances
// x k, coefficients / k, point and spot intensities x k^2 (k = 1e-3, 1e3), for
// every method, paired against scale 1; surfaces below unit scale.
#include "tests/render/stiff/stiff_case_groups.h"
#include "tests/render/stiff/stiff_case_support.h"

#include "tests/support/test_scenes.h"

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace vrl::stiff {
namespace {

// Media only: the null-bounded cube of mediumOnlyCube (isotropic) with its point
// light and a spot light inside, camera outside.
SceneDescription scaleCubeScene() {
    SceneDescription d = test::mediumOnlyCube(Rgb(0.8f), Rgb(0.2f), 0.0f);
    d.sensor.width = d.sensor.height = 8;
    EmitterDescription spot;
    spot.kind = EmitterDescription::Kind::Spot;
    spot.intensity = Rgb(6.0f, 4.0f, 2.0f);
    spot.cutoffAngle = 40.0f;
    spot.beamWidth = 30.0f;
    spot.medium = 0;
    spot.toWorld = Transform::lookAt(Vec3(-0.4f, 0.7f, -0.2f), Vec3(0.1f, -1.0f, 0.3f), Vec3(0, 0, 1));
    d.emitters.push_back(spot);
    return d;
}

// Surfaces: the lit room with an occluder (spot and area light) plus a point light, isotropic medium.
SceneDescription scaleRoomScene() {
    SceneDescription d = test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f);
    d.sensor.width = d.sensor.height = 8;
    EmitterDescription point;
    point.kind = EmitterDescription::Kind::Point;
    point.intensity = Rgb(2.0f, 3.0f, 4.0f);
    point.toWorld = Transform::translate(Vec3(-1.0f, 0.5f, 1.2f));
    d.emitters.push_back(point);
    return d;
}

// Distances x k, coefficients / k, point and spot intensities x k^2 (area radiance unchanged).
SceneDescription scaled(SceneDescription d, float k) {
    const Transform s = Transform::scale(Vec3(k));
    d.sensor.toWorld = d.sensor.toWorld.then(s);
    d.sensor.nearClip *= k;
    d.sensor.farClip *= k;
    for (auto& m : d.media) {
        m.sigmaS /= k;
        m.sigmaA /= k;
    }
    for (auto& shape : d.shapes) {
        shape.toWorld = shape.toWorld.then(s);
        shape.center *= k;
        shape.radius *= k;
    }
    for (auto& e : d.emitters) {
        e.toWorld = e.toWorld.then(s);
        e.intensity *= k * k;
    }
    return d;
}

// Renders with the same seeds at scale 1 and k: a paired t on the image means per
// channel, allowing 1e-4 relative (float rounding of the scaled scene). Identical
// seeds keep the two images close wherever the arithmetic is scale-invariant, so the
// test detects changes far below the noise of either image; where the images
// decorrelate the paired SE grows to about that noise, and the sample counts keep
// it near 1% of the mean.
void scaleCase(CaseResult& r, const std::string& method, float k, bool room) {
    r.description = format("scale invariance, %s: %s scaled by %g against scale 1 (distances x k, coefficients "
                           "/ k, point and spot intensities x k^2), same seeds, 8 runs, paired t on the image means",
                           method.c_str(),
                           room ? "the lit room (occluder, spot, point and area light)"
                                : "the medium-only cube (point and spot light inside)",
                           k);
    const SceneDescription d = room ? scaleRoomScene() : scaleCubeScene();
    const auto base = Scene::build(d);
    const auto other = Scene::build(scaled(d, k));
    RenderSettings settings = methodSettings(method, method == "path" ? 128 : 2, 1500);
    const ImageStats a = renderRuns(r, *base, settings, 8, 700);
    const ImageStats b = renderRuns(r, *other, settings, 8, 700);
    comparePaired(r, format("scale %g vs 1", k), b, a, 1e-4);
    note(r, format("relative difference of the image means (green) %.3g; %.2f s + %.2f s",
                   relativeDifference(a.mean.y, b.mean.y), a.seconds, b.seconds));
}

// Surface offsets below unit scale (they were absolute, 1e-4 units: twice the gap
// between the ceiling and the area light here; now relative to the hit
// triangle's coordinates): the lit room scaled by 1e-3, the camera looking at the
// ceiling around the area light, direct light and single scattering only
// (maxDepth 2), path tracer; paired against scale 1.
void smallRoomCase(CaseResult& r) {
    r.description = "scale invariance with surfaces below unit scale: the lit room scaled by 1e-3, camera looking at "
                    "the ceiling around the area light (maxDepth 2), path tracer, paired t against scale 1 (8 runs)";
    SceneDescription d = scaleRoomScene();
    d.sensor.toWorld = Transform::lookAt(Vec3(-0.8f, 1.2f, -0.4f), Vec3(-0.8f, 2.0f, 0.3f), Vec3(0, 0, 1));
    const auto base = Scene::build(d);
    const auto other = Scene::build(scaled(d, 1e-3f));
    RenderSettings settings = methodSettings("path", 64, 0);
    settings.maxDepth = 2;
    const ImageStats a = renderRuns(r, *base, settings, 8, 900);
    const ImageStats b = renderRuns(r, *other, settings, 8, 900);
    comparePaired(r, "scale 0.001 vs 1", b, a, 1e-4);
    note(r, format("relative difference of the image means (green) %.3g", relativeDifference(a.mean.y, b.mean.y)));
}

}  // namespace

std::vector<StiffCase> scaleCases() {
    std::vector<StiffCase> cases;
    const auto add = [&cases](const std::string& group, const std::string& name, std::function<void(CaseResult&)> f) {
        cases.push_back(makeCase(group, name, std::move(f)));
    };
    for (const std::string method : {"path", "vrl", "vrl-lightcuts", "vpl-lightcuts"})
        for (const float k : {1e-3f, 1e3f})
            add("scale", format("cube, %s, k = %g", method.c_str(), k),
                [method, k](CaseResult& r) { scaleCase(r, method, k, false); });
    for (const std::string method : {"path", "vrl", "vrl-lightcuts", "vpl-lightcuts"})
        add("scale", format("room, %s, k = 1000", method.c_str()),
            [method](CaseResult& r) { scaleCase(r, method, 1e3f, true); });
    cases.push_back({"scale", "room, ceiling by the area light, k = 0.001",
                     [](CaseResult& r, const CaseOptions&) { smallRoomCase(r); }, ""});
    return cases;
}

}  // namespace vrl::stiff
