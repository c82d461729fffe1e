// Stiff cases, group "geometry" (stiff_cases.h): camera rays parallel to,
// crossing, touching and collinear with VRLs; VRLs of length 1e-7 and 1e4;
// zero-length camera segments; a camera inside a dense medium; a point light
// inside the medium and near its boundary.
#include "tests/render/stiff/stiff_case_groups.h"
#include "tests/render/stiff/stiff_case_support.h"

#include "render/lightcuts/bounds/cluster_bound.h"
#include "render/lightcuts/cuts/vpl_lightcuts_estimator.h"
#include "render/lightcuts/cuts/lightcuts_estimator.h"
#include "tests/support/test_scenes.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace vrl::stiff {
namespace {

void parallelCase(CaseResult& r) {
    r.description = "camera ray parallel (and antiparallel) to a VRL at offsets 0.3, 1e-3, 1e-6, isotropic and HG "
                    "g = 0.7: estimator vs quadrature; tree of the parallel VRLs: bounds, threshold-0 cut";
    std::vector<Vrl> vrls;
    for (const float g : {0.0f, 0.7f}) {
        const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), g);
        int i = 0;
        for (const double offset : {0.3, 1e-3, 1e-6}) {
            for (const double sign : {1.0, -1.0}) {
                const Vrl v = makeVrl(V3d(offset, 0.0, sign > 0 ? 0.4 : 1.4), kZ3 * sign, 1.0);
                expectUnbiased(r, *scene, v, zSegment(), 50'000, 1400 + i++,
                               format("g %g, offset %g, %s", g, offset, sign > 0 ? "parallel" : "antiparallel"));
                if (g == 0.0f) vrls.push_back(v);
            }
        }
    }
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const LightTree tree = LightTree::build(vrls);
    const std::vector<CameraSegment> segments = {zSegment(), zSegment(1e30), makeSegment(V3d(0, 0, -5), kZ3, 3.0)};
    checkClusterBounds(r, *scene, tree, segments, 256, 1410);
    checkCutAgainstPlain(r, *scene, tree, segments, 1411, "parallel tree");
}

// A VRL along +x through the point (0, offset, 1) (crossing the z axis at z = 1 when offset = 0).
Vrl crossingVrl(double offset) { return makeVrl(V3d(-0.5, offset, 0.85), V3d(1, 0, 0.3), 1.0); }

void crossingCase(CaseResult& r) {
    r.description = "VRL crossing the camera ray: near-crossing at 1e-2, 1e-4, 1e-6 vs quadrature (the integral "
                    "grows like log(1/offset)); exact crossing: finite samples, infinite bound, cut = plain";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    int i = 0;
    double previous = 0.0;
    for (const double offset : {1e-2, 1e-4, 1e-6}) {
        const Vrl v = crossingVrl(offset);
        expectUnbiased(r, *scene, v, zSegment(), 100'000, 1500 + i++, format("offset %g", offset));
        const double q = reference(v, zSegment(), paramsOf(scene->media()[0])).value.x;
        require(r, q > previous, "the near-crossing integral must grow as the offset shrinks");
        previous = q;
    }
    const VrlEstimator estimator(*scene, 1);
    const SampleStats exact = sampleEstimator(r, estimator, crossingVrl(0.0), zSegment(), 100'000, 1510);
    note(r, format("exact crossing: sample mean %.4g (true integral infinite), largest sample %.3g", exact.mean.x,
                   exact.maxSample));
    std::vector<Vrl> vrls = {crossingVrl(0.0), crossingVrl(1e-6), crossingVrl(1e-2)};
    Rng rng(1511, 0);
    for (int k = 0; k < 13; ++k) vrls.push_back(makeVrl(uniformInCube(rng, 1.0), uniformDirection(rng), 0.5));
    const LightTree tree = LightTree::build(vrls);
    const ClusterBound bound(*scene, tree);
    bool crosses = false;
    bound.bound(0, zSegment(), &crosses);
    require(r, crosses, "the exactly crossing VRL's leaf must report a crossing (infinite bound)");
    checkClusterBounds(r, *scene, tree, {zSegment(), zSegment(1e30)}, 256, 1512);
    checkCutAgainstPlain(r, *scene, tree, {zSegment(), zSegment(1e30)}, 1513, "crossing tree");
}

void touchingCase(CaseResult& r) {
    r.description = "touching: VRL starting on / ending on the camera segment, camera segment starting on the VRL "
                    "(finite, >= 0, infinite bound, cut = plain); near-touching at 1e-6 vs quadrature";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const VrlEstimator estimator(*scene, 1);
    const V3d dir(1, 0, 0.2);
    const Vrl starts = makeVrl(V3d(0, 0, 1.0), dir, 1.0);
    const Vrl ends = makeVrl(V3d(0, 0, 1.0) - dir.normalized() * 1.0, dir, 1.0);
    const Vrl nearStart = makeVrl(V3d(1e-6, 0, 1.0), dir, 1.0);
    const CameraSegment fromVrl = makeSegment(toD(crossingVrl(0.0).origin) + V3d(1, 0, 0.3).normalized() * 0.5,
                                              V3d(0, 1, 0), 2.0);
    for (const auto& [vrl, seg, name] : {std::tuple{starts, zSegment(), "VRL starting on the segment"},
                                         std::tuple{ends, zSegment(), "VRL ending on the segment"},
                                         std::tuple{crossingVrl(0.0), fromVrl, "segment starting on the VRL"}}) {
        const SampleStats s = sampleEstimator(r, estimator, vrl, seg, 50'000, 1600);
        note(r, format("%s: sample mean %.4g (true integral infinite)", name, s.mean.x));
        const LightTree single = LightTree::build({vrl});
        bool crosses = false;
        ClusterBound(*scene, single).bound(0, seg, &crosses);
        require(r, crosses, std::string(name) + ": the bound must be infinite");
    }
    expectUnbiased(r, *scene, nearStart, zSegment(), 100'000, 1601, "VRL starting 1e-6 from the segment");
    const LightTree tree = LightTree::build({starts, ends, nearStart, crossingVrl(0.0)});
    checkCutAgainstPlain(r, *scene, tree, {zSegment(), fromVrl}, 1602, "touching tree");
    checkClusterBounds(r, *scene, tree, {zSegment(), fromVrl}, 256, 1603);
}

// Collinear and disjoint: the VRL on the camera line beyond the segment's end
// (both directions). Both phase cosines are +-1, so
//   L = Tb Phi sigma_s^2 fV fU int_0^t e^{-sigma_t p(v)} (1 / (p - S) - 1 / p) dv,  p(v) = a +- v,
// a 1D integral (Gauss-Legendre, 64 panels; smooth since p - S >= 0.5).
double collinearReference(double a, double sign, double t, double S, const MediumParams& m, int c,
                          double before) {
    const double fV = hg(m.g, -sign), fU = hg(m.g, 1.0);
    const V3d v = gaussLegendre(
        [&](double x) {
            const double p = a + sign * x;
            return V3d(std::exp(-m.sigmaT[c] * p) * (1.0 / (p - S) - 1.0 / p));
        },
        0.0, t, 64);
    return before * m.sigmaS[c] * m.sigmaS[c] * fV * fU * v.x;
}

void collinearCase(CaseResult& r) {
    r.description = "collinear: VRL on the camera line beyond the segment, same and opposite direction, isotropic "
                    "and HG g = +-0.9, vs the closed-form 1D integral; VRL lying on the segment (infinite "
                    "integral): finite samples, infinite bound, cut = plain";
    int i = 0;
    for (const float g : {0.0f, 0.9f, -0.9f}) {
        const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), g);
        const VrlEstimator estimator(*scene, 1);
        const MediumParams m = paramsOf(scene->media()[0]);
        for (const double sign : {1.0, -1.0}) {
            const double a = sign > 0 ? 2.5 : 3.5;  // the VRL covers z in [2.5, 3.5] either way
            const Vrl v = makeVrl(V3d(0, 0, a), kZ3 * sign, 1.0);
            const SampleStats s = sampleEstimator(r, estimator, v, zSegment(), 100'000, 1700 + i++);
            for (int c = 0; c < 3; ++c) {
                const double ref = collinearReference(a, sign, 1.0, 2.0, m, c, 0.9);
                compare(r, format("g %g, %s, channel %d: z (mean %.5g, analytic %.5g)", g,
                                  sign > 0 ? "same direction" : "opposite direction", c, s.mean[c], ref),
                        zScore(s.mean[c], s.se[c], ref, 1e-5 * ref), kZ);
            }
        }
    }
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const VrlEstimator estimator(*scene, 1);
    const Vrl on = makeVrl(V3d(0, 0, 0.5), kZ3, 1.0);
    const SampleStats s = sampleEstimator(r, estimator, on, zSegment(), 50'000, 1710);
    note(r, format("VRL on the segment: sample mean %.4g (true integral infinite)", s.mean.x));
    std::vector<Vrl> vrls = {on, makeVrl(V3d(0, 0, 2.5), kZ3, 1.0), makeVrl(V3d(0, 0, -1.5), -kZ3, 1.0),
                             makeVrl(V3d(0, 0, 0.2), -kZ3, 0.1)};
    const LightTree tree = LightTree::build(vrls);
    const ClusterBound bound(*scene, tree);
    for (size_t n = 0; n < tree.nodes().size(); ++n) {
        bool crosses = false;
        bound.bound(int32_t(n), zSegment(), &crosses);
        require(r, crosses, "every node on the camera line must have an infinite bound");
    }
    checkCutAgainstPlain(r, *scene, tree, {zSegment(), makeSegment(V3d(0.1, 0, 0), kZ3, 2.0)}, 1711, "collinear tree");
    checkClusterBounds(r, *scene, tree, {makeSegment(V3d(0.1, 0, 0), kZ3, 2.0)}, 256, 1712);
}

void shortVrlCase(CaseResult& r) {
    r.description = "VRLs of length 1e-7 (generic, 1e-3 from the camera line, parallel 1e-3 away) vs quadrature; a "
                    "tree of 1e-7 VRLs (cluster flux = flux x length / 1e-7): bounds, threshold-0 cut";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const std::vector<std::pair<Vrl, const char*>> cases = {
        {makeVrl(V3d(0.3, 0.2, 0.7), V3d(1, 2, 3), 1e-7), "generic"},
        {makeVrl(V3d(1e-3, 0, 0.7), V3d(0, 1, 0), 1e-7), "1e-3 from the line"},
        {makeVrl(V3d(1e-3, 0, 0.7), kZ3, 1e-7), "parallel, 1e-3 away"}};
    int i = 0;
    for (const auto& [v, name] : cases) expectUnbiased(r, *scene, v, zSegment(), 50'000, 1800 + i++, name);
    std::vector<Vrl> vrls;
    Rng rng(1810, 0);
    for (int k = 0; k < 24; ++k) vrls.push_back(makeVrl(uniformInCube(rng, 1.0), uniformDirection(rng), 1e-7));
    const LightTree tree = LightTree::build(vrls);
    for (const LightTreeNode& node : tree.nodes()) {
        checkValue(r, node.clusterFlux);
        checkValue(r, node.fluxLength);
    }
    std::vector<CameraSegment> segments = {zSegment()};
    for (int k = 0; k < 3; ++k) segments.push_back(makeSegment(uniformInCube(rng, 1.0), uniformDirection(rng), 2.0));
    checkClusterBounds(r, *scene, tree, segments, 64, 1811);
    checkCutAgainstPlain(r, *scene, tree, segments, 1812, "1e-7 tree");
}

void longVrlCase(CaseResult& r) {
    r.description = "VRLs of length 1e4 passing 0.05 and 1 from the camera segment's middle, sigma_t = 1e-3 and 1, "
                    "vs quadrature; tree of long and short VRLs: bounds, threshold-0 cut";
    int i = 0;
    std::vector<Vrl> vrls;
    for (const double sigmaT : {1e-3, 1.0}) {
        const auto scene = unboundedScene(Rgb(float(0.5 * sigmaT)), Rgb(float(0.5 * sigmaT)), 0.0f);
        for (const double h : {0.05, 1.0}) {
            const V3d dir = V3d(1, 0.3, 0).normalized();
            const Vrl v = makeVrl(V3d(0, h, 1.0) - dir * 5000.0, dir, 1e4);
            expectUnbiased(r, *scene, v, zSegment(), 100'000, 1900 + i++, format("sigma_t %g, h %g", sigmaT, h));
            if (sigmaT == 1.0) vrls.push_back(v);
        }
    }
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.5f), 0.0f);
    Rng rng(1910, 0);
    for (int k = 0; k < 14; ++k) vrls.push_back(makeVrl(uniformInCube(rng, 2.0), uniformDirection(rng), 0.5));
    const LightTree tree = LightTree::build(vrls);
    const std::vector<CameraSegment> segments = {zSegment(), zSegment(1e30), makeSegment(V3d(3, 3, 3), V3d(-1, -1, -1), 6.0)};
    checkClusterBounds(r, *scene, tree, segments, 64, 1911);
    checkCutAgainstPlain(r, *scene, tree, segments, 1912, "long tree");
}

void zeroLengthSegmentCase(CaseResult& r) {
    r.description = "camera segments of length 0, 1e-40 (denormal), 1e-30, 1e-20: VRL, Lightcuts and VPL "
                    "Lightcuts estimates finite, >= 0, exactly 0 at length 0, and below the analytic bound "
                    "(ClusterBound, proportional to the length); lengths 1e-7 and 1e-4 vs quadrature";
    const auto scene = unboundedScene(Rgb(0.5f), Rgb(0.2f), 0.0f);
    const VrlEstimator estimator(*scene, 1);
    Rng rng(2000, 0);
    std::vector<Vrl> vrls, vpls;
    for (int k = 0; k < 32; ++k) {
        vrls.push_back(makeVrl(uniformInCube(rng, 1.0), uniformDirection(rng), 0.5));
        Vrl p = vrls.back();
        p.length = 0.0f;
        vpls.push_back(p);
    }
    const LightTree tree = LightTree::build(vrls);
    const LightTree points = LightTree::build(vpls, LightTreeSettings{2048, 0, true});
    const LightcutsEstimator cut(*scene, tree, estimator, CutSettings{});
    const VplLightcutsEstimator vplCut(*scene, points, CutSettings{});
    const ClusterBound bound(*scene, tree);
    double worstRatio = 0.0;
    for (const float length : {0.0f, 1e-40f, 1e-30f, 1e-20f}) {
        for (int k = 0; k < 4; ++k) {
            CameraSegment seg = makeSegment(uniformInCube(rng, 1.5), uniformDirection(rng), 1.0);
            seg.length = length;
            CutStatistics statistics;
            const Rgb c = cut.estimate(seg, 7 + k, statistics);
            Rng vplRng(2001, uint64_t(k));
            const Rgb p = vplCut.estimate(seg, vplRng, statistics);
            checkValue(r, c);
            checkValue(r, p);
            if (length == 0.0f) {
                require(r, isBlack(c) && isBlack(p), "a zero-length segment must contribute exactly 0");
            }
            for (size_t j = 0; j < vrls.size(); ++j) {
                Rng vr(2002, j);
                const Rgb e = estimator.contribution(vrls[j], seg, vr);
                checkValue(r, e);
                if (length == 0.0f) require(r, isBlack(e), "a zero-length segment must contribute exactly 0");
                bool crosses = false;
                const Rgb b = bound.bound(int32_t(j), seg, &crosses);
                if (crosses) continue;
                ++r.boundChecks;
                if (e.x > b.x || e.y > b.y || e.z > b.z) ++r.boundViolations;
                if (b.x > 0.0f) worstRatio = std::max(worstRatio, double(e.x) / double(b.x));
            }
        }
    }
    compare(r, "largest estimate / analytic bound", worstRatio, 1.0);
    // Short but resolvable segments against the quadrature.
    int i = 0;
    for (const double length : {1e-7, 1e-4}) {
        const CameraSegment seg = makeSegment(V3d(0.1, -0.2, 0.3), V3d(1, 1, 0), length);
        const Vrl v = makeVrl(V3d(0.5, 0.1, 0.2), V3d(0, 1, 1), 0.8);
        expectUnbiased(r, *scene, v, seg, 50'000, 2010 + i++, format("segment length %g", length));
    }
}

// Image level, the camera inside a dense medium: a null-bounded cube of half-size
// 1e-3 (10 mean free paths at sigma_t = 1e4, albedo 0.9), the camera 3 mean free
// paths inside its -z face looking out through it, a point light in the vacuum
// 5e-4 beyond the face (so the path tracer's next-event estimation has finite
// variance). Every VRL method against the path tracer (8 runs each).
void denseCameraCase(CaseResult& r) {
    r.description = "camera inside a dense medium (sigma_t = 1e4, albedo 0.9, cube of half-size 1e-3), 3 mean free "
                    "paths from the face it looks out of, point light in the vacuum beyond: vrl, vrl-lightcuts, "
                    "vpl-lightcuts vs the path tracer (8 runs)";
    SceneDescription d;
    d.sensor = test::cameraAtOrigin(4, 4, 70.0f);
    d.sensor.toWorld = Transform::lookAt(Vec3(0.0f, 0.0f, -0.7e-3f), Vec3(0.0f, 0.0f, -1.0f), Vec3(0, 1, 0));
    d.sensor.nearClip = 1e-8f;
    d.sensor.medium = 0;
    d.media.push_back(mediumDescription(Rgb(9e3f), Rgb(1e3f), 0.0f));
    ShapeDescription cube;
    cube.kind = ShapeDescription::Kind::Cube;
    cube.toWorld = Transform::scale(Vec3(1e-3f));
    cube.bsdf = test::nullBsdf();
    cube.interiorMedium = 0;
    d.shapes.push_back(cube);
    EmitterDescription light;
    light.kind = EmitterDescription::Kind::Point;
    light.intensity = Rgb(2.5e-7f);
    light.toWorld = Transform::translate(Vec3(1e-4f, 0.5e-4f, -1.5e-3f));
    d.emitters.push_back(light);
    const auto scene = Scene::build(d);
    const ImageStats reference = renderRuns(r, *scene, methodSettings("path", 1024, 0), 8, 200);
    note(r, format("path: mean %.5g +- %.2g, %.2f s", reference.mean.x, reference.se.x, reference.seconds));
    for (const std::string method : {"vrl", "vrl-lightcuts", "vpl-lightcuts"}) {
        const ImageStats s = renderRuns(r, *scene, methodSettings(method, 16, 4000), 8, 300);
        compareRuns(r, method + " vs path", s, reference);
        note(r, format("%s: mean %.5g +- %.2g, %.2f s", method.c_str(), s.mean.x, s.se.x, s.seconds));
    }
}

SceneDescription cubeWithLightAt(const Vec3& position, int emitterMedium) {
    SceneDescription d = test::mediumOnlyCube(Rgb(0.8f), Rgb(0.2f), 0.0f);
    d.sensor.width = d.sensor.height = 6;
    d.emitters[0].toWorld = Transform::translate(position);
    d.emitters[0].medium = emitterMedium;
    return d;
}

// The point light inside the medium cube (mediumOnlyCube): VRL methods against the
// path tracer. Its next-event estimation from vertices near a point light in a
// medium has infinite variance (weights ~ 1 / d^2), so its standard error is an
// underestimate; 1024 samples per pixel keep that small.
void lightInsideCase(CaseResult& r) {
    r.description = "point light inside a null-bounded medium cube (sigma_s 0.8, sigma_a 0.2), camera outside: vrl, "
                    "vrl-lightcuts, vpl-lightcuts vs the path tracer (8 runs)";
    const auto scene = Scene::build(cubeWithLightAt(Vec3(0.2f, 0.5f, 0.3f), 0));
    const ImageStats reference = renderRuns(r, *scene, methodSettings("path", 1024, 0), 8, 400);
    note(r, format("path: mean %.5g +- %.2g, %.2f s", reference.mean.y, reference.se.y, reference.seconds));
    for (const std::string method : {"vrl", "vrl-lightcuts", "vpl-lightcuts"}) {
        const ImageStats s = renderRuns(r, *scene, methodSettings(method, 16, 4000), 8, 500);
        compareRuns(r, method + " vs path", s, reference);
        note(r, format("%s: mean %.5g +- %.2g, %.2f s", method.c_str(), s.mean.y, s.se.y, s.seconds));
    }
}

// The point light 1e-6 inside / exactly on / 1e-3 outside the cube's top face (y = 1),
// its medium located by the scene, against the same light 1e-3 inside (same seeds:
// a paired comparison per method). Moving the light by 1e-3 changes the image by far
// less than the 1% allowed (the light just outside the face reaches the medium
// through 1e-3 of vacuum instead of medium).
void lightNearBoundaryCase(CaseResult& r, float depth, const char* what) {
    r.description = format("point light %s of a medium cube (medium located by the scene), camera outside: "
                           "every method against the light 1e-3 inside the face, same seeds (paired, 8 runs, 1%% "
                           "allowed for the move)",
                           what);
    const auto scene = Scene::build(cubeWithLightAt(Vec3(0.2f, 1.0f - depth, 0.3f), -1));
    const auto reference = Scene::build(cubeWithLightAt(Vec3(0.2f, 1.0f - 1e-3f, 0.3f), -1));
    note(r, format("emitter medium %d (reference %d)", scene->emitters()[0]->medium, reference->emitters()[0]->medium));
    for (const std::string& method : kAllMethods) {
        const RenderSettings settings = methodSettings(method, method == "path" ? 32 : 2, 2000);
        const ImageStats a = renderRuns(r, *scene, settings, 8, 600);
        const ImageStats b = renderRuns(r, *reference, settings, 8, 600);
        comparePaired(r, method, a, b, 0.01);
    }
}

}  // namespace

std::vector<StiffCase> geometryCases() {
    std::vector<StiffCase> cases;
    const auto add = [&cases](const std::string& group, const std::string& name, std::function<void(CaseResult&)> f) {
        cases.push_back(makeCase(group, name, std::move(f)));
    };
    add("geometry", "parallel", parallelCase);
    add("geometry", "crossing", crossingCase);
    add("geometry", "touching", touchingCase);
    add("geometry", "collinear", collinearCase);
    add("geometry", "VRL length 1e-7", shortVrlCase);
    add("geometry", "VRL length 1e4", longVrlCase);
    add("geometry", "zero-length camera segment", zeroLengthSegmentCase);
    add("geometry", "camera inside dense medium", denseCameraCase);
    add("geometry", "light inside the medium", lightInsideCase);
    add("geometry", "light 1e-6 inside the boundary",
        [](CaseResult& r) { lightNearBoundaryCase(r, 1e-6f, "1e-6 inside the top face"); });
    add("geometry", "light on the boundary",
        [](CaseResult& r) { lightNearBoundaryCase(r, 0.0f, "exactly on the top face"); });
    add("geometry", "light 1e-3 outside the boundary",
        [](CaseResult& r) { lightNearBoundaryCase(r, -1e-3f, "1e-3 outside the top face (in the vacuum)"); });
    return cases;
}

}  // namespace vrl::stiff
