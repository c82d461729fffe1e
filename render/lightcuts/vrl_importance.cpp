#include "render/lightcuts/vrl_importance.h"

#include "render/core/distance.h"
#include "render/scene/scene.h"

#include <algorithm>
#include <cmath>

namespace vrl {

namespace {

// The box's diagonal, and a floor for distances at the scale of the coordinates.
double diagonal(const Imath::Box3f& box) { return double((box.max - box.min).length()); }
double tinyDistance(const Vec3& p, const Imath::Box3f& box) {
    const double reach = std::max({std::abs(box.min.x), std::abs(box.min.y), std::abs(box.min.z),
                                   std::abs(box.max.x), std::abs(box.max.y), std::abs(box.max.z)});
    return 1e-6 * (1.0 + double(p.length()) + reach);
}


double largestChannel(const Rgb& c) { return double(std::max({c.x, c.y, c.z})); }

}  // namespace

VrlImportance::VrlImportance(const Scene& scene, const LightTree& tree, float minimumDistanceFraction)
    : scene_(scene), tree_(tree), fraction_(minimumDistanceFraction) {
    for (const auto& m : scene.media())
        for (int c = 0; c < 3; ++c) maxSigmaS_[c] = std::max(maxSigmaS_[c], m.sigmaS()[c]);
}

double VrlImportance::weight(const LightTreeNode& node) const {
    const Rgb sigmaS = node.medium >= 0 ? scene_.media()[node.medium].sigmaS() : maxSigmaS_;
    return double(luminance(node.fluxLength * sigmaS));
}

double VrlImportance::segment(int32_t index, const CameraSegment& segment) const {
    const LightTreeNode& node = tree_.nodes()[index];
    const double w = weight(node);
    if (!(w > 0.0)) return 0.0;
    const double hBox = distanceLineBox(segment.origin, segment.direction, node.box);
    const double h = std::max({hBox, double(fraction_) * diagonal(node.box), tinyDistance(segment.origin, node.box)});
    // The box's projection onto the line, and the foot point nearest the segment's middle.
    const Vec3 centre = node.box.center();
    const Vec3 half = (node.box.max - node.box.min) * 0.5f;
    const double tc = double(segment.direction.dot(centre - segment.origin));
    const double r = std::abs(double(segment.direction.x)) * half.x + std::abs(double(segment.direction.y)) * half.y +
                     std::abs(double(segment.direction.z)) * half.z;
    const double S = double(segment.length);
    const double t = std::clamp(0.5 * S, tc - r, tc + r);
    // The angle thetaB - thetaA = atan(b) + atan(a), a = t / h, b = (S - t) / h, is
    // atan2(a + b, 1 - a b) (a + b = S / h > 0: in (0, pi)), and the tangent of its
    // middle direction, tan((thetaA + thetaB) / 2) = tan((atan b - atan a) / 2), is
    // (b - a) / (sqrt((1 + a^2)(1 + b^2)) + 1 + a b) (tan(x/2) = sin x / (1 + cos x)):
    // one atan2 where two atans and a tan were.
    const double a = t / h, b = (S - t) / h;
    const double angle = std::atan2(S / h, 1.0 - a * b);
    const double middleTangent = (b - a) / (std::sqrt((1.0 + a * a) * (1.0 + b * b)) + 1.0 + a * b);
    double transmittance = 1.0;
    const HomogeneousMedium& medium = scene_.media()[segment.medium];
    if (node.medium == segment.medium && medium.boundaryConvex())
        transmittance = largestChannel(medium.transmittance(float(hBox)));
    return w * transmittance * std::max(angle, 0.0) / h * phaseFactor(index, segment, centre, t + h * middleTangent);
}

double VrlImportance::phaseFactor(int32_t index, const CameraSegment& segment, const Vec3& centre, double u) const {
    const LightTreeNode& node = tree_.nodes()[index];
    // Henyey-Greenstein media: the phase functions towards the point u of the camera
    // line in the middle of the subtended angle, relative to isotropic (4 pi)^2 f f:
    // the camera side for every node whose box is small seen from there, the VRL side
    // for single VRLs (an inner node's VRL directions are unknown: isotropic).
    const HomogeneousMedium& cameraMedium = scene_.media()[segment.medium];
    const HomogeneousMedium* vrlMedium = node.medium >= 0 ? &scene_.media()[node.medium] : nullptr;
    const bool anisotropic = !cameraMedium.phase().isIsotropic() || !vrlMedium || !vrlMedium->phase().isIsotropic();
    if (!anisotropic) return 1.0;
    const Vec3 toU = segment.origin + segment.direction * float(u) - centre;
    const float distance = toU.length();
    const float radius = 0.5f * (node.box.max - node.box.min).length();
    if (!(distance > 2.0f * radius) || !(distance > 0.0f)) return 1.0;
    const Vec3 w = toU / distance;
    double factor = 4.0 * M_PI * double(cameraMedium.phase().eval(w, -segment.direction));
    if (node.isLeaf() && vrlMedium) factor *= 4.0 * M_PI * double(vrlMedium->phase().eval(tree_.vrls()[size_t(index)].direction, w));
    return factor;
}

double VrlImportance::surface(int32_t index, const CameraPathSurface& x) const {
    const LightTreeNode& node = tree_.nodes()[index];
    const double w = weight(node);
    if (!(w > 0.0)) return 0.0;
    const Vec3& p = x.hit.position;
    const SceneShape& shape = scene_.shapes()[x.hit.shape];
    const bool reflectsOnly = shape.bsdf.kind() != BsdfDescription::Kind::RoughDielectric;
    const double tiny = tinyDistance(p, node.box);
    const float side = x.wo.dot(x.hit.geometricNormal) >= 0.0f ? 1.0f : -1.0f;
    // Wholly behind a reflecting surface (with the bound's rounding slack): exactly 0.
    if (reflectsOnly && signedDistanceRange(node.box, x.hit.geometricNormal * side, p).second < -8.0 * tiny) return 0.0;
    const double dBox = distancePointBox(p, node.box);
    const double d = std::max({dBox, double(fraction_) * diagonal(node.box), tiny});
    const auto [lo, hi] = signedDistanceRange(node.box, x.hit.shadingNormal, p);
    const double cosine = std::clamp(std::max(std::abs(lo), std::abs(hi)) / std::max(dBox, tiny), 1e-3, 1.0);
    double transmittance = 1.0;
    if (node.medium >= 0 && node.medium == x.medium && reflectsOnly && !shape.changesMedium) {
        const HomogeneousMedium& medium = scene_.media()[node.medium];
        if (medium.boundaryConvex()) transmittance = largestChannel(medium.transmittance(float(dBox)));
    }
    // A single VRL in an anisotropic medium: its phase function towards x (4 pi f_V).
    double phase = 1.0;
    if (node.isLeaf() && node.medium >= 0 && !scene_.media()[node.medium].phase().isIsotropic()) {
        const Vrl& vrl = tree_.vrls()[size_t(index)];
        const Vec3 toX = p - (vrl.origin + vrl.direction * (0.5f * vrl.length));
        const float length = toX.length();
        if (length > 0.0f) phase = 4.0 * M_PI * double(scene_.media()[node.medium].phase().eval(vrl.direction, toX / length));
    }
    return w * cosine * transmittance * phase / (d * d);
}

}  // namespace vrl
