#include "render/integrators/transport_integrator.h"

#include "render/vrl/camera_segment.h"
#include "render/vrl/vrl_estimator.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <optional>
#include <span>
#include <stdexcept>

namespace vrl {

namespace {
// Interleaved points on one shape whose geometric normals agree to within about 0.8
// degrees, and whose offset lies in that plane to within about 0.06 degrees (not two
// parallel faces of one mesh, such as two treads of a staircase), are one flat piece
// of surface (interleavedSurface).
constexpr float kCoherentNormalCosine = 0.9999f;
constexpr float kCoplanarSine = 1e-3f;

bool onePiece(const CameraPathSurface& a, const CameraPathSurface& b) {
    if (a.specularBefore != 0 || b.specularBefore != 0 || a.hit.shape != b.hit.shape) return false;
    if (!(a.hit.geometricNormal.dot(b.hit.geometricNormal) > kCoherentNormalCosine)) return false;
    const Vec3 offset = b.hit.position - a.hit.position;
    return std::abs(a.hit.geometricNormal.dot(offset)) <= kCoplanarSine * offset.length();
}
}  // namespace

TransportIntegrator::TransportIntegrator(const Scene& scene, const VrlSet& vrls,
                                         const TransportIntegratorSettings& settings, const LightTree* tree,
                                         const SurfaceVplLights* surfaceVpls)
    : scene_(scene),
      settings_(settings),
      tracer_(scene, PathTracerSettings{settings.maxDepth}),
      gatherers_(makeGatherers(scene, settings.transports, settings.estimators,
                               GathererInputs{&vrls.vrls, tree, surfaceVpls, settings.vrlSamples, settings.cut,
                                              settings.vplDistanceSamples})) {
    if (const SurfaceVplLight* light = gatherers_.surfaceVpls.get()) {
        surfaceVplsSingle_ = settings.transports.has(TransportPart::Single);
        // (a) samples the VPLs down their tree: only with one.
        if (settings.transports.has(TransportPart::Surface) && !surfaceVpls->vpls.empty() && light->hasTree())
            surfaceVplRadius_ = ::vrl::surfaceVplRadius(*surfaceVpls);
    }
    if (settings.maxDepth >= 0 && settings.maxDepth < 16 && scene.hasSpecularSurfaces() &&
        (settings.transports.has(TransportPart::Multiple) || gatherers_.surfaceVpls ||
         (vrlLitSurfaces() && settings.transports.has(TransportPart::MediumSurface))))
        spdlog::warn("maxDepth {} with specular surfaces: the VRL parts (c), (d) (and the surface VPLs' light in (a), "
                     "(b)) seen through glass or mirrors do not count the specular bounces towards maxDepth",
                     settings.maxDepth);
}

std::array<Rgb, 4> TransportIntegrator::samplePathParts(const Ray& cameraRay, Rng& rng) const {
    std::array<Rgb, 4> parts{Rgb(0.0f), Rgb(0.0f), Rgb(0.0f), Rgb(0.0f)};
    using After = PathStart::AfterFirstSurface;
    if (settings_.transports.has(TransportPart::Surface)) {
        PathStart start{0, true, true, true, After::NotInMedium};
        start.surfaceVplRadius = surfaceVplRadius_;  // 0 without surface VPLs for (a)
        parts[size_t(TransportPart::Surface)] = tracer_.radiance(cameraRay, scene_.cameraMedium(), rng, start);
        if (surfaceVplRadius_ > 0.0f) parts[size_t(TransportPart::Surface)] += surfaceVplsAtSurface(cameraRay, rng);
    }
    if (!vrlLitSurfaces() && settings_.transports.has(TransportPart::MediumSurface))
        parts[size_t(TransportPart::MediumSurface)] = tracer_.radiance(
            cameraRay, scene_.cameraMedium(), rng, PathStart{0, true, false, true, After::InMedium});
    if (!settings_.transports.has(TransportPart::Single)) return parts;
    for (const CameraSegment& segment : cameraSegments(scene_, cameraRay, scene_.cameraMedium(), &rng, settings_.maxDepth)) {
        if (scene_.media()[segment.medium].isNonScattering()) continue;
        parts[size_t(TransportPart::Single)] += singleScattering(segment, rng);
        parts[size_t(TransportPart::Single)] += mediumToSurface(segment, rng);
    }
    return parts;
}

Rgb TransportIntegrator::singleScattering(const CameraSegment& segment, Rng& rng) const {
    if (settings_.maxDepth >= 0 && settings_.maxDepth < segment.specularBefore + 2) return Rgb(0.0f);
    const EmitterSampler& sampler = scene_.emitterSampler();
    if (sampler.empty()) return Rgb(0.0f);
    const auto [index, probability] = sampler.sample(rng.next());
    const Emitter& emitter = *scene_.emitters()[index];
    // Equiangular towards a point of the light (its position, or a random point of an area light).
    const Vec3 towards = emitter.sampleDirect(segment.origin, Vec2(rng.next(), rng.next())).position;
    const DistanceSample us = sampleEquiangular(segment.origin, segment.direction, segment.length, towards, rng.next());
    if (!(us.pdf > 0.0f)) return Rgb(0.0f);
    const Vec3 x = segment.origin + segment.direction * us.t;
    const DirectLightSample light = emitter.sampleDirect(x, Vec2(rng.next(), rng.next()));
    if (isBlack(light.weight)) return Rgb(0.0f);
    const Rgb toLight = scene_.transmittance(x, light.position, segment.medium);
    if (isBlack(toLight)) return Rgb(0.0f);
    const HomogeneousMedium& medium = scene_.media()[segment.medium];
    const float phase = medium.phase().eval(-light.direction, -segment.direction);
    return segment.throughputBefore * medium.transmittance(us.t) * medium.sigmaS() * light.weight * toLight *
           (phase / (probability * us.pdf));
}

Rgb TransportIntegrator::mediumToSurface(const CameraSegment& segment, Rng& rng) const {
    if (settings_.maxDepth >= 0 && settings_.maxDepth < segment.specularBefore + 3) return Rgb(0.0f);
    const HomogeneousMedium& medium = scene_.media()[segment.medium];
    // u on [0, length] from one channel's truncated exponential, chosen uniformly;
    // the pdf is the average over channels (spectral MIS), so no channel's
    // transmittance outruns its density in chromatic media.
    const double length = segment.length;
    const auto truncatedPdf = [&](double sigma, double u) {
        if (sigma * length < 1e-6) return 1.0 / length;
        return sigma * std::exp(-sigma * u) / -std::expm1(-sigma * length);
    };
    const int channel = std::min(2, int(rng.next() * 3.0f));
    const double sigmaChannel = medium.sigmaT()[channel], xi = rng.next();
    const double u = sigmaChannel * length < 1e-6
                         ? xi * length
                         : std::min(length, -std::log1p(xi * std::expm1(-sigmaChannel * length)) / sigmaChannel);
    double pdf = 0.0;
    for (int c = 0; c < 3; ++c) pdf += truncatedPdf(medium.sigmaT()[c], u) / 3.0;
    if (!(pdf > 0.0) || !std::isfinite(pdf)) return Rgb(0.0f);
    const Vec3 x = segment.origin + segment.direction * float(u);
    const PhaseSample next = medium.phase().sample(segment.direction, Vec2(rng.next(), rng.next()));
    // Exact transmittance to the next surface, reflected light only: a path that
    // scatters again in the medium first belongs to (d), emission at the surface to
    // (b)'s single scattering. With surface VPLs, only what leaves that surface by a
    // Dirac lobe: the VPLs bring the rest (virtualLightParts).
    PathStart start{1 + segment.specularBefore, true, false};
    start.diracAtFirstSurfaceOnly = surfaceVplsLight();
    const Rgb reflected = tracer_.radiance(Ray{x, next.direction}, segment.medium, rng, start);
    return segment.throughputBefore * medium.transmittance(float(u)) * medium.sigmaS() * reflected *
           float(1.0 / pdf);
}

TransportIntegrator::VirtualLightParts TransportIntegrator::virtualLightParts(const Ray& cameraRay, Rng& rng,
                                                                           CutStatistics* multipleStatistics,
                                                                           CutStatistics* surfaceStatistics,
                                                                           float pathLuminance,
                                                                           CutStatistics* surfaceVplStatistics,
                                                                           const FilmSquare* pixel) const {
    VirtualLightParts parts;
    const bool multiple = settings_.transports.has(TransportPart::Multiple);
    const bool surface = vrlLitSurfaces() && settings_.transports.has(TransportPart::MediumSurface);
    if (!multiple && !surface && !surfaceVplsLight()) return parts;
    CutStatistics unused;
    // One stream family per camera segment (and one for the surface x1); VRL k draws
    // from (key, k) in both plain and Lightcuts shading, so the two differ only by
    // the cut's approximation.
    const uint64_t pixelKey = (uint64_t(rng.nextUint()) << 32) | rng.nextUint();
    CameraPath path = cameraPath(scene_, cameraRay, scene_.cameraMedium(), &rng, settings_.maxDepth);
    // (d) first: (c)'s cut measures its error against the pixel's other parts. (d)'s own
    // cuts measure theirs against their total and the path-sampled parts (Lightcuts'
    // error relative to the pixel; the paper's media-only images have only (d)).
    uint64_t segmentIndex = 0;
    for (const CameraSegment& segment : path.segments) {
        if (!multiple) break;
        const uint64_t streamKey = Rng::combine(pixelKey, segmentIndex++);
        if (scene_.media()[segment.medium].isNonScattering()) continue;
        CutStatistics& statistics = multipleStatistics ? *multipleStatistics : unused;
        parts.multiple += gatherers_.multiple->gather(segment, streamKey, statistics, pathLuminance);
    }
    if (surface) {
        CutStatistics& statistics = surfaceStatistics ? *surfaceStatistics : unused;
        const float other = pathLuminance + std::max(0.0f, luminance(parts.multiple));
        if (pixel && settings_.surfacePointsSide > 1 && gatherers_.mediumSurface->interleaves()) {
            parts.mediumSurface = interleavedSurface(*pixel, pixelKey, statistics, other);
        } else if (path.surface) {
            if (pixel) averageTextures(*path.surface, std::span<const FilmSquare>(pixel, 1));
            parts.mediumSurface = vrlLitSurface(InterleavedPoints::single(*path.surface),
                                                Rng::combine(pixelKey, ~uint64_t(0)), statistics, other);
        }
    }
    // (b)'s surface light from the VPLs, last: its cut measures its error against the pixel's other parts.
    if (surfaceVplsSingle_) {
        const float other = pathLuminance + std::max(0.0f, luminance(parts.multiple)) +
                            std::max(0.0f, luminance(parts.mediumSurface));
        CutStatistics& statistics = surfaceVplStatistics ? *surfaceVplStatistics : unused;
        segmentIndex = 0;
        for (const CameraSegment& segment : path.segments) {
            // A stream family apart from (d)'s: (key of segment i) with the top bit set.
            const uint64_t streamKey = Rng::combine(pixelKey, segmentIndex++ | (uint64_t(1) << 63));
            if (scene_.media()[segment.medium].isNonScattering()) continue;
            if (settings_.maxDepth >= 0 && settings_.maxDepth < segment.specularBefore + 3) continue;
            parts.singleSurface += gatherers_.surfaceVpls->alongSegment(
                segment, streamKey, statistics, other + std::max(0.0f, luminance(parts.singleSurface)));
        }
    }
    return parts;
}

Rgb TransportIntegrator::surfaceVplsAtSurface(const Ray& cameraRay, Rng& rng) const {
    // The sample's own camera path to its x1 (its own specular choices: the path tracer's x1
    // estimates the complement, each unbiased on its own).
    const CameraPath path = cameraPath(scene_, cameraRay, scene_.cameraMedium(), &rng, settings_.maxDepth);
    if (!path.surface) return Rgb(0.0f);
    // A depth limit: the VPLs hold light paths of k + 2 <= maxDepth segments (light_tracer.h); the
    // camera's specular bounces are not counted (the warning above), and where even x2's NEE is
    // past the limit the path tracer has nothing to hand to them either.
    if (settings_.maxDepth >= 0 && settings_.maxDepth < path.surface->specularBefore + 3) return Rgb(0.0f);
    return gatherers_.surfaceVpls->atSurface(*path.surface, surfaceVplRadius_, rng);
}

void TransportIntegrator::averageTextures(CameraPathSurface& x, std::span<const FilmSquare> squares) const {
    if (x.specularBefore != 0 || !scene_.shapes()[x.hit.shape].bsdf.isTextured()) return;
    std::array<Vec2, size_t(kFootprintPoints) * InterleavedPoints::kMaxPoints> uvs;
    size_t count = 0;
    for (const FilmSquare& square : squares) {
        if (count + kFootprintPoints > uvs.size()) break;
        if (const auto footprint = footprintTexcoords(scene_, square, x.hit)) {
            std::copy(footprint->begin(), footprint->end(), uvs.begin() + std::ptrdiff_t(count));
            count += kFootprintPoints;
        }
    }
    x.bsdf.averageTexturesOver(std::span<const Vec2>(uvs.data(), count));
}

Rgb TransportIntegrator::interleavedSurface(const FilmSquare& square, uint64_t pixelKey, CutStatistics& statistics,
                                            float otherLuminance) const {
    const int side = settings_.surfacePointsSide;
    const uint32_t count = uint32_t(side * side);
    if (count > InterleavedPoints::kMaxPoints) throw std::logic_error("interleavedSurface: too many points");
    // The points' own stream (jitter, specular choices, o and the representatives), apart
    // from the pixel's other draws.
    Rng rng = vrlStream(Rng::combine(pixelKey, ~uint64_t(1)), 0);
    std::array<std::optional<CameraPathSurface>, InterleavedPoints::kMaxPoints> surfaces;
    std::array<FilmSquare, InterleavedPoints::kMaxPoints> strata;
    const float stratum = square.size / float(side);
    for (uint32_t q = 0; q < count; ++q) {
        strata[q] = FilmSquare{square.x + float(q % uint32_t(side)) * stratum,
                               square.y + float(q / uint32_t(side)) * stratum, stratum};
        const float jx = rng.next(), jy = rng.next();
        const Ray ray = scene_.camera().generateRay(strata[q].x + jx * stratum, strata[q].y + jy * stratum);
        CameraPath path = cameraPath(scene_, ray, scene_.cameraMedium(), &rng, settings_.maxDepth);
        if (!path.surface) continue;
        // Past the depth limit the point has no (c) (as vrlLitSurface's single point).
        if (settings_.maxDepth >= 0 && settings_.maxDepth < path.surface->specularBefore + 3) continue;
        surfaces[q] = std::move(path.surface);
    }
    const uint32_t offset = std::min(count - 1, uint32_t(rng.next() * float(count)));
    const uint64_t streamKey = Rng::combine(pixelKey, ~uint64_t(0));
    // Classes of coherent points (interleaved_points.h): a point seen directly joins the
    // first class whose first point lies on the same shape, with the same geometric
    // normal, in the same plane (one flat piece of surface, where the points differ by
    // little but their texels); any other present point (through glass, a mirror) is a
    // class of its own.
    std::array<int32_t, InterleavedPoints::kMaxPoints> classOf;
    std::array<uint32_t, InterleavedPoints::kMaxPoints> firstOf{}, sizeOf{};
    classOf.fill(-1);
    uint32_t classes = 0;
    for (uint32_t q = 0; q < count; ++q) {
        if (!surfaces[q]) continue;
        const CameraPathSurface& p = *surfaces[q];
        int32_t c = -1;
        for (uint32_t j = 0; j < classes && c < 0; ++j)
            if (onePiece(*surfaces[firstOf[j]], p)) c = int32_t(j);
        if (c < 0) c = int32_t(classes), firstOf[classes++] = q;
        classOf[q] = c;
        ++sizeOf[uint32_t(c)];
    }
    if (classes == 1 && sizeOf[0] == count) {
        // Inside a surface: point o (uniform over the four), with its textures averaged
        // over the whole square, at the cost of one cut.
        CameraPathSurface& one = *surfaces[offset];
        averageTextures(one, std::span<const FilmSquare>(&square, 1));
        return vrlLitSurface(InterleavedPoints::single(one), streamKey, statistics, otherLuminance);
    }
    // Elsewhere (an edge, a silhouette, a fold, glass, a point that escapes) each class
    // is represented by one of its points, drawn uniformly, with its textures averaged
    // over its class's strata; VRL k goes to the representative of point (k + o) mod Q's
    // class, the cut bounded at the representatives (as many bounds per node as classes).
    InterleavedPoints points;
    points.count = count;
    points.offset = offset;
    std::array<CameraPathSurface*, InterleavedPoints::kMaxPoints> representative{};
    for (uint32_t c = 0; c < classes; ++c) {
        const uint32_t pick = std::min(sizeOf[c] - 1, uint32_t(rng.next() * float(sizeOf[c])));
        std::array<FilmSquare, InterleavedPoints::kMaxPoints> squares;
        uint32_t members = 0;
        for (uint32_t q = 0; q < count; ++q) {
            if (classOf[q] != int32_t(c)) continue;
            if (members == pick) representative[c] = &*surfaces[q];
            squares[members++] = strata[q];
        }
        averageTextures(*representative[c], std::span<const FilmSquare>(squares.data(), members));
    }
    for (uint32_t q = 0; q < count; ++q)
        points.points[q] = classOf[q] >= 0 ? representative[uint32_t(classOf[q])] : nullptr;
    return vrlLitSurface(points, streamKey, statistics, otherLuminance);
}

Rgb TransportIntegrator::vrlLitSurface(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
                                       float otherLuminance) const {
    if (points.count == 1 &&
        (!points.points[0] ||
         (settings_.maxDepth >= 0 && settings_.maxDepth < points.points[0]->specularBefore + 3)))
        return Rgb(0.0f);
    return gatherers_.mediumSurface->gather(points, streamKey, statistics, otherLuminance);
}

}  // namespace vrl
