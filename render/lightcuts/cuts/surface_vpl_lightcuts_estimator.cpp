#include "render/lightcuts/cuts/surface_vpl_lightcuts_estimator.h"

#include "render/core/distance.h"
#include "render/lightcuts/cuts/cut_walk.h"
#include "render/lightcuts/cuts/stochastic_cut.h"
#include "render/lightcuts/bounds/surface_cluster_bound.h"
#include "render/vrl/vrl_estimator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace vrl {

namespace {

constexpr double kRoundingMargin = 1.001;

}  // namespace

Rgb surfaceVplReflectionBound(const Scene& scene, const SurfaceVpl& vpl) {
    const SurfaceVplEstimator estimator(scene);
    if (const std::optional<Rgb> bound = estimator.reflectionBound(vpl)) return *bound;
    // Glossy lobes: a heuristic (surface_vpl_lightcuts_estimator.h).
    const Bsdf& bsdf = scene.shapes()[vpl.shape].bsdf;
    const SurfaceHit hit = surfaceHitOf(vpl);
    const Vec3 wo = -vpl.direction;
    Vec3 n = vpl.shadingNormal;
    if (wo.dot(n) < 0.0f) n = -n;
    const Vec3 mirror = (n * (2.0f * wo.dot(n)) - wo).normalized();
    Rgb largest(0.0f);
    for (const Vec3& w : {mirror, n, -mirror, -n}) {
        const Rgb f = bsdf.eval(hit.shadingPoint(), wo, w, TransportMode::Importance);
        largest = componentMax(largest, f);
    }
    return largest * 2.0f;
}

float surfaceVplRadius(const SurfaceVplLights& lights) {
    if (lights.vpls.empty()) return 0.0f;
    Imath::Box3f box;
    for (const SurfaceVpl& vpl : lights.vpls) box.extendBy(vpl.position);
    const float diagonal = (box.max - box.min).length();
    return diagonal > 0.0f && std::isfinite(diagonal) ? kSurfaceVplRadiusFraction * diagonal : 0.0f;
}

SurfaceVplLights prepareSurfaceVpls(const Scene& scene, std::vector<SurfaceVpl> vpls, bool buildTree,
                                    const LightTreeSettings& settings) {
    SurfaceVplLights lights;
    std::vector<Vrl> proxies;
    size_t kept = 0;
    for (size_t k = 0; k < vpls.size(); ++k) {
        const Rgb intensity = vpls[k].flux * surfaceVplReflectionBound(scene, vpls[k]);
        if (!(maxComponent(intensity) > 0.0f) || !isFinite(intensity)) continue;
        vpls[kept++] = vpls[k];
        // The proxy's medium: the VPL's, where its shape bounds no medium (light leaves it
        // into that medium whichever side it reflects to), else -1 (no transmittance bound).
        const int medium = scene.shapes()[vpls[k].shape].changesMedium ? -1 : vpls[k].medium;
        if (buildTree) proxies.push_back(Vrl{vpls[k].position, vpls[k].direction, 0.0f, intensity, medium});
    }
    vpls.resize(kept);
    vpls.shrink_to_fit();
    lights.vpls = std::move(vpls);
    if (buildTree) {
        LightTreeSettings points = settings;
        points.points = true;
        lights.tree = LightTree::build(std::move(proxies), points);
    }
    return lights;
}

SurfaceVplLightcutsEstimator::SurfaceVplLightcutsEstimator(const Scene& scene, const SurfaceVplLights& lights,
                                                           const SurfaceVplEstimator& estimator, CutSettings settings)
    : scene_(scene), lights_(lights), estimator_(estimator), settings_(settings) {
    const LightTree& tree = lights.tree;
    if (tree.empty()) return;
    reflection_.reserve(lights.vpls.size());
    atVpl_.reserve(lights.vpls.size());
    for (const SurfaceVpl& vpl : lights.vpls) {
        reflection_.push_back(surfaceVplReflectionBound(scene, vpl));
        atVpl_.push_back(estimator.prepareAt(vpl));
    }
    const auto& nodes = tree.nodes();
    normals_.assign(nodes.size(), NormalBound{});
    broadIntensity_.assign(nodes.size(), Rgb(0.0f));
    // Post-order from the root (children before their parent), without recursion.
    std::vector<std::pair<int32_t, bool>> stack{{tree.root(), false}};
    while (!stack.empty()) {
        const auto [i, childrenDone] = stack.back();
        stack.pop_back();
        const LightTreeNode& node = nodes[size_t(i)];
        if (node.isLeaf()) {
            const SurfaceVpl& vpl = lights.vpls[node.representative];
            const bool lambertian = lambertianBounded(scene.shapes()[vpl.shape].bsdf);
            normals_[size_t(i)] = NormalBound{vpl.geometricNormal, lambertian ? 0.0f : -1.0f};
            if (reflectsBroadly(scene.shapes()[vpl.shape].bsdf)) broadIntensity_[size_t(i)] = node.clusterFlux;
            continue;
        }
        if (!childrenDone) {
            stack.push_back({i, true});
            stack.push_back({node.left, false});
            stack.push_back({node.right, false});
            continue;
        }
        broadIntensity_[size_t(i)] = broadIntensity_[size_t(node.left)] + broadIntensity_[size_t(node.right)];
        const NormalBound& l = normals_[size_t(node.left)];
        const NormalBound& r = normals_[size_t(node.right)];
        if (l.spread < 0.0f || r.spread < 0.0f) continue;  // stays "no cosine factor"
        // |n_k - a_l| <= |n_k - a_r| + |a_r - a_l| for the right child's VPLs.
        normals_[size_t(i)] = NormalBound{l.axis, std::max(l.spread, r.spread + (r.axis - l.axis).length())};
    }
}

Rgb SurfaceVplLightcutsEstimator::bound(int32_t index, const CameraSegment& segment) const {
    const LightTreeNode& node = lights_.tree.nodes()[size_t(index)];
    const HomogeneousMedium& medium = scene_.media()[size_t(segment.medium)];
    // Rounding: distances are computed in double from float boxes; shrink them by a
    // relative margin of the coordinates' size.
    const float reach = std::max({std::abs(node.box.min.x), std::abs(node.box.min.y), std::abs(node.box.min.z),
                                  std::abs(node.box.max.x), std::abs(node.box.max.y), std::abs(node.box.max.z)});
    const double slack = 8.0 * 0x1p-24 * (double(segment.origin.length()) + reach);
    const SegmentBoxDistances distances =
        distancesSegmentBox(segment.origin, segment.direction, double(segment.length), node.box);
    const double dLine = distances.line - slack, dSegment = distances.segment - slack;
    double geometry = std::numeric_limits<double>::infinity();
    // The angle a segment of length S subtends from distance h is at most 2 atan(S / 2h) (<= pi).
    if (dLine > 0.0) geometry = maxSubtendedAngle(segment.length, dLine) / dLine;
    if (dSegment > 0.0) geometry = std::min(geometry, double(segment.length) / (dSegment * dSegment));
    if (!std::isfinite(geometry)) return Rgb(std::numeric_limits<float>::infinity());
    // The cosine at y (surface_vpl_lightcuts_estimator.h), for nodes of Lambertian VPLs with nearly one normal.
    if (!normals_.empty() && normals_[size_t(index)].spread >= 0.0f && normals_[size_t(index)].spread < 1.0f) {
        const NormalBound& n = normals_[size_t(index)];
        const auto [boxLow, boxHigh] = signedDistanceRange(node.box, n.axis, segment.origin);
        const double along = double(n.axis.dot(segment.direction)) * double(segment.length);
        const double h = std::max({0.0, std::max(0.0, along) - boxLow, boxHigh - std::min(0.0, along)}) + slack;
        if (dSegment > 0.0) geometry *= std::min(1.0, h / dSegment + double(n.spread));
    }
    // Transmittance (surface_vpl_lightcuts_estimator.h): T_m(t) T_r = exp(-sigma_t (t + r)) <= exp(-sigma_t d_o).
    Rgb transmittance(1.0f);
    if (node.medium == segment.medium && medium.boundaryConvex()) {
        const double dOrigin = distancePointBox(segment.origin, node.box) - slack;
        if (dOrigin > 0.0) transmittance = medium.transmittanceBound(dOrigin);
    }
    const double g = std::abs(double(medium.phase().g()));
    const double phaseMax = medium.phase().isIsotropic() ? double(kInv4Pi) : double(kInv4Pi) * (1.0 + g) / ((1.0 - g) * (1.0 - g));
    return node.clusterFlux * medium.sigmaS() * segment.throughputBefore * transmittance *
           float(kRoundingMargin * phaseMax * geometry);
}

std::array<double, 3> SurfaceVplLightcutsEstimator::pointBound(int32_t index, const CameraPathSurface& x,
                                                              float radius) const {
    const LightTreeNode& node = lights_.tree.nodes()[size_t(index)];
    const Rgb& intensity = broadIntensity_[size_t(index)];  // only the VPLs part (a) takes
    if (isBlack(intensity)) return {0.0, 0.0, 0.0};
    const Vec3& p = x.hit.position;
    const float reach = std::max({std::abs(node.box.min.x), std::abs(node.box.min.y), std::abs(node.box.min.z),
                                  std::abs(node.box.max.x), std::abs(node.box.max.y), std::abs(node.box.max.z)});
    const double slack = 8.0 * 0x1p-24 * (double(p.length()) + reach);
    const double d = distancePointBox(p, node.box) - slack;
    // reflectionTowardsBox takes a positive distance: a tiny one where x may lie in the box (cosine bound 1).
    const double dPositive = d > 0.0 ? d : 1e-30;
    const SceneShape& shape = scene_.shapes()[x.hit.shape];
    const Rgb fCos = SurfaceClusterBound::reflectionTowardsBox(x, shape.bsdf, node.box, dPositive, slack,
                                                               settings_.bound);
    if (isBlack(fCos)) return {0.0, 0.0, 0.0};
    double cosine = 1.0;  // at y (surface_vpl_lightcuts_estimator.h)
    if (d > 0.0 && !normals_.empty() && normals_[size_t(index)].spread >= 0.0f && normals_[size_t(index)].spread < 1.0f) {
        const NormalBound& n = normals_[size_t(index)];
        const auto [lo, hi] = signedDistanceRange(node.box, n.axis, p);
        cosine = std::min(1.0, (std::max(std::abs(lo), std::abs(hi)) + slack) / d + double(n.spread));
    }
    Rgb transmittance(1.0f);
    const bool reflectsOnly = shape.bsdf.kind() != BsdfDescription::Kind::RoughDielectric;
    if (d > 0.0 && node.medium >= 0 && node.medium == x.medium && reflectsOnly && !shape.changesMedium &&
        scene_.media()[size_t(node.medium)].boundaryConvex())
        transmittance = scene_.media()[size_t(node.medium)].transmittanceBound(d);
    const double clamped = std::max(std::max(d, 0.0), double(radius));
    // In double: a float product of these factors could round to 0 where the VPLs still
    // contribute denormals, and an importance of 0 beside a positive sibling is never drawn.
    const double scale = kRoundingMargin * cosine / (clamped * clamped);
    std::array<double, 3> b{};
    for (int c = 0; c < 3; ++c)
        b[size_t(c)] = double(intensity[c]) * double(fCos[c]) * double(transmittance[c]) * double(x.throughput[c]) * scale;
    return b;
}

Rgb SurfaceVplLightcutsEstimator::bound(int32_t index, const CameraPathSurface& x, float radius) const {
    const std::array<double, 3> b = pointBound(index, x, radius);
    return Rgb(float(b[0]), float(b[1]), float(b[2]));
}

ChildImportances SurfaceVplLightcutsEstimator::importances(int32_t node, const CameraPathSurface& x,
                                                          float radius) const {
    const LightTreeNode& n = lights_.tree.nodes()[size_t(node)];
    const auto importanceOf = [&](int32_t child) {
        const std::array<double, 3> b = pointBound(child, x, radius);
        return b[0] + b[1] + b[2];
    };
    return ChildImportances{{n.left, n.right}, {importanceOf(n.left), importanceOf(n.right)}};
}

Rgb SurfaceVplLightcutsEstimator::sample(const CameraPathSurface& x, float radius, uint32_t cutSize, Rng& rng,
                                         CutStatistics& statistics) const {
    const LightTree& tree = lights_.tree;
    if (tree.empty() || !(radius > 0.0f) || !lambertianBounded(scene_.shapes()[x.hit.shape].bsdf)) return Rgb(0.0f);
    return stochasticCutEstimate(
        tree, cutSize, rng, statistics, [&](int32_t node) { return importances(node, x, radius); },
        [&](const int32_t* leaves, size_t count, Rng&, Rgb* out) {
            for (size_t k = 0; k < count; ++k) {
                const SurfaceVpl& vpl = lights_.vpls[size_t(leaves[k])];
                out[k] = estimator_.contribution(vpl, atVpl_[size_t(leaves[k])], vpl.flux, x, radius);
            }
        });
}

Rgb SurfaceVplLightcutsEstimator::representativeFlux(const LightTreeNode& node) const {
    // Phi_r I_C / I_r = I_C / F_r where Phi_r > 0, and also where the representative
    // carries no flux in a channel (a null collision of spectral tracking weighs 0
    // there): its BSDF bound still scales the cluster's light in that channel.
    const Rgb& reflection = reflection_[node.representative];
    const auto scaled = [](float cluster, float bound) { return bound > 0.0f ? cluster / bound : 0.0f; };
    return Rgb(scaled(node.clusterFlux.x, reflection.x), scaled(node.clusterFlux.y, reflection.y),
               scaled(node.clusterFlux.z, reflection.z));
}

Rgb SurfaceVplLightcutsEstimator::estimate(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                                           float otherLuminance) const {
    const LightTree& tree = lights_.tree;
    if (tree.empty() || !(segment.length > 0.0f)) return Rgb(0.0f);
    if (scene_.media()[size_t(segment.medium)].isNonScattering()) return Rgb(0.0f);
    struct Visitor {
        const SurfaceVplLightcutsEstimator& self;
        const CameraSegment& segment;
        uint64_t streamKey;
        Rgb leaf(int32_t i) const {
            const uint32_t k = self.lights_.tree.nodes()[size_t(i)].representative;
            Rng rng = vrlStream(streamKey, k);
            return self.estimator_.contribution(self.lights_.vpls[k], self.atVpl_[k], self.lights_.vpls[k].flux, segment,
                                                rng);
        }
        bool bound(int32_t i, Rgb& b) const {
            b = self.bound(i, segment);
            return std::isfinite(b.x + b.y + b.z);
        }
        Rgb estimate(int32_t i) const {
            const LightTreeNode& node = self.lights_.tree.nodes()[size_t(i)];
            const uint32_t k = node.representative;
            Rng rng = vrlStream(streamKey, k);
            return self.estimator_.contribution(self.lights_.vpls[k], self.atVpl_[k], self.representativeFlux(node),
                                                segment, rng);
        }
    };
    return walkCut(tree, settings_, statistics, Visitor{*this, segment, streamKey}, otherLuminance);
}

Rgb SurfaceVplLightcutsEstimator::sumAll(const CameraSegment& segment, uint64_t streamKey) const {
    // atVpl_ holds one BSDF per VPL where the estimator has a tree (the constructor), else none.
    const bool prepared = atVpl_.size() == lights_.vpls.size();
    return sumOverSurfaceVpls(estimator_, lights_.vpls, segment, streamKey, prepared ? &atVpl_ : nullptr);
}

Rgb sumOverSurfaceVpls(const SurfaceVplEstimator& estimator, const std::vector<SurfaceVpl>& vpls,
                       const CameraSegment& segment, uint64_t streamKey, const std::vector<PreparedBsdf>* prepared) {
    if (prepared && prepared->size() != vpls.size())
        throw std::invalid_argument("sumOverSurfaceVpls: " + std::to_string(prepared->size()) +
                                    " prepared BSDFs for " + std::to_string(vpls.size()) + " VPLs");
    Rgb sum(0.0f);
    for (uint32_t k = 0; k < vpls.size(); ++k) {
        Rng rng = vrlStream(streamKey, k);
        sum += prepared ? estimator.contribution(vpls[k], (*prepared)[k], vpls[k].flux, segment, rng)
                        : estimator.contribution(vpls[k], segment, rng);
    }
    return sum;
}

Rgb sumOverSurfaceVpls(const SurfaceVplEstimator& estimator, const std::vector<SurfaceVpl>& vpls,
                       const CameraPathSurface& x, float radius) {
    Rgb sum(0.0f);
    for (const SurfaceVpl& vpl : vpls) sum += estimator.contribution(vpl, vpl.flux, x, radius);
    return sum;
}

}  // namespace vrl
