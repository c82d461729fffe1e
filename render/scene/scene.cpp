#include "render/scene/scene.h"

#include "render/shapes/shape_mesh.h"

#include <Imath/ImathBox.h>
#include <embree3/rtcore.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>
#include <string>

namespace vrl {

struct Scene::Embree {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::string firstError;

    ~Embree() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

namespace {

constexpr int kLocateMedium = -2;  // placeholder until the BVH can locate an emitter's medium

// Embree context carrying the triangles a continued ray must ignore (Ray::skip).
struct SkipContext {
    RTCIntersectContext context;
    const Ray* ray;
};

void skipCrossedShape(const RTCFilterFunctionNArguments* args) {
    const Ray& ray = *reinterpret_cast<const SkipContext*>(args->context)->ray;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0 || !(RTCRayN_tfar(args->ray, args->N, i) < ray.skipUntil)) continue;
        const uint32_t shape = RTCHitN_geomID(args->hit, args->N, i), triangle = RTCHitN_primID(args->hit, args->N, i);
        for (int k = 0; k < ray.skipCount; ++k) {
            if (ray.skip[k].shape == shape && ray.skip[k].triangle == triangle) args->valid[i] = 0;
        }
    }
}

void embreeErrorCallback(void* userData, RTCError code, const char* message) {
    auto* embree = static_cast<std::string*>(userData);
    spdlog::error("Embree error {}: {}", int(code), message ? message : "");
    if (embree->empty()) embree->assign(message ? message : "unknown Embree error");
}

Bsdf makeBsdf(const ShapeDescription& shape, std::span<const std::shared_ptr<const Texture>> textures) {
    if (shape.bsdf) {
        for (const auto& c : {shape.bsdf->reflectance, shape.bsdf->specularReflectance, shape.bsdf->specularTransmittance})
            if (c.texture >= int(textures.size())) throw SceneError(shape.where, "texture index out of range");
        try {
            return Bsdf(*shape.bsdf, textures);
        } catch (const std::invalid_argument& e) {
            throw SceneError(shape.where, e.what());
        }
    }
    // Mitsuba: a bare shape between media is an invisible boundary.
    if ((shape.interiorMedium >= 0 || shape.exteriorMedium >= 0) && !shape.areaRadiance) return Bsdf::null();
    return Bsdf();
}

PhaseFunction makePhase(const PhaseDescription& phase) {
    return phase.kind == PhaseDescription::Kind::HenyeyGreenstein ? PhaseFunction::henyeyGreenstein(phase.g)
                                                                  : PhaseFunction::isotropic();
}

// True if every vertex lies on the inner side of every triangle's plane.
bool isConvexClosed(const std::vector<const TriangleMesh*>& meshes) {
    size_t work = 0;
    for (const auto* m : meshes) work += m->triangles.size();
    size_t vertices = 0;
    for (const auto* m : meshes) vertices += m->positions.size();
    if (work * vertices > 200'000'000) return false;  // too large to check: assume not convex
    for (const auto* m : meshes) {
        for (size_t i = 0; i < m->triangles.size(); ++i) {
            if (m->triangleArea(i) <= 0.0f) continue;
            const Vec3 n = m->geometricNormal(i);
            const Vec3 p0 = m->positions[m->triangles[i][0]];
            for (const auto* other : meshes) {
                for (const Vec3& p : other->positions) {
                    if (n.dot(p - p0) > 1e-4f * positionScale(p)) return false;
                }
            }
        }
    }
    return true;
}

// Media declared separately with equal coefficients and phase are one physical
// medium (Mitsuba scenes often repeat an inline <medium> on every shape that
// touches it): one index for all, so that crossings between them change nothing
// and light-tree nodes and cluster bounds see a single medium.
SceneDescription mergeIdenticalMedia(SceneDescription d) {
    std::vector<int> canonical(d.media.size());
    std::vector<MediumDescription> unique;
    for (size_t i = 0; i < d.media.size(); ++i) {
        const MediumDescription& m = d.media[i];
        const auto same = std::find_if(unique.begin(), unique.end(), [&](const MediumDescription& u) {
            return u.sigmaS == m.sigmaS && u.sigmaA == m.sigmaA && u.phase.kind == m.phase.kind && u.phase.g == m.phase.g;
        });
        canonical[i] = int(same - unique.begin());
        if (same == unique.end()) unique.push_back(m);
    }
    if (unique.size() == d.media.size()) return d;
    spdlog::info("{}: {} media declared, {} distinct: identical ones are treated as one", d.file.string(),
                 d.media.size(), unique.size());
    const auto remap = [&](int& index) {
        if (index >= 0 && index < int(canonical.size())) index = canonical[index];
    };
    remap(d.sensor.medium);
    for (auto& s : d.shapes) {
        remap(s.interiorMedium);
        remap(s.exteriorMedium);
    }
    for (auto& e : d.emitters) remap(e.medium);
    d.media = std::move(unique);
    return d;
}

}  // namespace

Scene::Scene(const SceneDescription& description) : description_(description), camera_(description.sensor) {}

Scene::~Scene() = default;

std::unique_ptr<Scene> Scene::build(const SceneDescription& declared) {
    const SceneDescription description = mergeIdenticalMedia(declared);
    std::unique_ptr<Scene> scene(new Scene(description));
    for (const auto& m : description.media) {
        try {
            scene->media_.emplace_back(m.id, m.sigmaS, m.sigmaA, makePhase(m.phase));
        } catch (const std::invalid_argument& e) {
            throw SceneError(m.where, e.what());
        }
    }
    const auto checkMedium = [&](int index, const SourceLocation& where) {
        if (index < -1 || index >= int(scene->media_.size()))
            throw SceneError(where, "medium index " + std::to_string(index) + " out of range");
    };
    checkMedium(description.sensor.medium, description.sensor.where);
    // In turn: OpenImageIO 2.4 cannot open JPEG files concurrently (Texture::load).
    scene->textures_.reserve(description.textures.size());
    for (const TextureDescription& texture : description.textures) scene->textures_.push_back(Texture::load(texture));
    for (const auto& note : description.approximations) spdlog::warn("approximation: {}", note);
    scene->shapes_.reserve(description.shapes.size());
    for (const auto& s : description.shapes) {
        checkMedium(s.interiorMedium, s.where);
        checkMedium(s.exteriorMedium, s.where);
        SceneShape shape;
        shape.mesh = buildShapeMesh(s);
        shape.bsdf = makeBsdf(s, scene->textures_);
        shape.interiorMedium = s.interiorMedium;
        shape.exteriorMedium = s.exteriorMedium;
        shape.changesMedium = s.interiorMedium >= 0 || s.exteriorMedium >= 0;
        scene->hasNullSurfaces_ = scene->hasNullSurfaces_ || shape.bsdf.isNull();
        scene->hasSpecularSurfaces_ = scene->hasSpecularSurfaces_ || shape.bsdf.isPurelySpecular();
        scene->shapes_.push_back(std::move(shape));
    }
    // Area emitters reference their mesh: create them only once shapes_ is final.
    for (size_t i = 0; i < description.shapes.size(); ++i) {
        const auto& radiance = description.shapes[i].areaRadiance;
        if (!radiance || isBlack(*radiance)) continue;
        auto emitter = makeAreaEmitter(scene->shapes_[i].mesh, *radiance);
        // The side it emits into; a shape that declares no media is located after the BVH is built.
        const auto& shape = description.shapes[i];
        emitter->medium = shape.interiorMedium >= 0 || shape.exteriorMedium >= 0 ? shape.exteriorMedium : kLocateMedium;
        scene->shapes_[i].emitter = int(scene->emitters_.size());
        scene->emitters_.push_back(std::move(emitter));
    }
    for (const auto& e : description.emitters) {
        checkMedium(e.medium, e.where);
        std::unique_ptr<Emitter> emitter;
        if (e.kind == EmitterDescription::Kind::Point)
            emitter = makePointEmitter(e.toWorld.applyPoint(Vec3(0.0f)), e.intensity);
        else
            emitter = makeSpotEmitter(e.toWorld, e.intensity, e.cutoffAngle, e.beamWidth);
        emitter->medium = e.medium >= 0 ? e.medium : kLocateMedium;
        scene->emitters_.push_back(std::move(emitter));
    }
    if (scene->emitters_.empty()) spdlog::warn("{}: the scene has no emitters; the image will be black", description.file.string());
    std::vector<const Emitter*> emitters;
    for (const auto& e : scene->emitters_) emitters.push_back(e.get());
    scene->emitterSampler_ = std::make_unique<EmitterSampler>(emitters);
    scene->classifyMediumBoundaries();
    scene->buildBvh();
    // Emitters that declare no medium: the one reached by walking from the camera
    // to them through the declared boundaries (light tracing starts there).
    for (size_t k = 0; k < scene->emitters_.size(); ++k) {
        Emitter& emitter = *scene->emitters_[k];
        if (emitter.medium != kLocateMedium) continue;
        const EmissionSample probe = emitter.sampleEmission(Vec2(0.5f, 0.5f), Vec2(0.0f, 0.0f));
        const Vec3& p = probe.ray.origin;
        const float step = 1e-4f * positionScale(p);
        emitter.medium = scene->mediumAt(p + probe.ray.direction * step);
    }
    return scene;
}

void Scene::classifyMediumBoundaries() {
    mediumNeedsVisibility_.assign(media_.size(), true);
    for (size_t m = 0; m < media_.size(); ++m) {
        std::vector<const TriangleMesh*> bounding;
        std::vector<size_t> boundingShapes;
        bool enclosesOtherRegion = false;
        for (size_t i = 0; i < shapes_.size(); ++i) {
            const auto& s = shapes_[i];
            if (s.interiorMedium == int(m)) boundingShapes.push_back(i);
            if (!s.bsdf.isNull()) continue;  // opaque walls: segments through them have V = 0 anyway
            if (s.exteriorMedium == int(m)) enclosesOtherRegion = true;
            if (s.interiorMedium == int(m)) bounding.push_back(&s.mesh);
        }
        const bool convex = !enclosesOtherRegion && (bounding.empty() || isConvexClosed(bounding));
        media_[m].setBoundaryConvex(convex);
        // Occlusion-free: no shapes at all, or a convex boundary (all shapes that have the
        // medium inside) whose box no other shape's box overlaps.
        if (shapes_.empty()) {
            mediumNeedsVisibility_[m] = false;
            continue;
        }
        if (!convex || boundingShapes.empty()) continue;
        std::vector<const TriangleMesh*> boundary;
        for (size_t i : boundingShapes) boundary.push_back(&shapes_[i].mesh);
        if (!isConvexClosed(boundary)) continue;
        Imath::Box3f box;
        for (const auto* mesh : boundary)
            for (const auto& p : mesh->positions) box.extendBy(p);
        bool somethingInside = false;
        for (size_t i = 0; i < shapes_.size() && !somethingInside; ++i) {
            if (std::find(boundingShapes.begin(), boundingShapes.end(), i) != boundingShapes.end()) continue;
            Imath::Box3f other;
            for (const auto& p : shapes_[i].mesh.positions) other.extendBy(p);
            somethingInside = box.intersects(other);
        }
        mediumNeedsVisibility_[m] = somethingInside;
    }
}

void Scene::buildBvh() {
    embree_ = std::make_unique<Embree>();
    embree_->device = rtcNewDevice(nullptr);
    if (!embree_->device) throw std::runtime_error("cannot create the Embree device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(embree_->device, embreeErrorCallback, &embree_->firstError);
    embree_->scene = rtcNewScene(embree_->device);
    rtcSetSceneFlags(embree_->scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(embree_->scene, RTC_BUILD_QUALITY_HIGH);
    for (size_t i = 0; i < shapes_.size(); ++i) {
        const TriangleMesh& mesh = shapes_[i].mesh;
        RTCGeometry geometry = rtcNewGeometry(embree_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                                     RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                                     mesh.positions.size()));
        auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0,
                                                                       RTC_FORMAT_UINT3, 3 * sizeof(uint32_t),
                                                                       mesh.triangles.size()));
        if (!vertices || !indices) {
            rtcReleaseGeometry(geometry);
            throw std::runtime_error("Embree could not allocate geometry buffers: " + embree_->firstError);
        }
        for (size_t v = 0; v < mesh.positions.size(); ++v) {
            vertices[3 * v] = mesh.positions[v].x;
            vertices[3 * v + 1] = mesh.positions[v].y;
            vertices[3 * v + 2] = mesh.positions[v].z;
        }
        for (size_t t = 0; t < mesh.triangles.size(); ++t)
            for (int k = 0; k < 3; ++k) indices[3 * t + k] = mesh.triangles[t][k];
        rtcCommitGeometry(geometry);
        rtcAttachGeometryByID(embree_->scene, geometry, unsigned(i));
        rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(embree_->scene);
    if (!embree_->firstError.empty()) throw std::runtime_error("Embree failed to build the scene: " + embree_->firstError);
}

std::optional<SurfaceHit> Scene::intersect(const Ray& ray) const {
    if (shapes_.empty()) return std::nullopt;
    SkipContext skip{};
    rtcInitIntersectContext(&skip.context);
    if (ray.skipCount > 0) {
        skip.context.filter = skipCrossedShape;
        skip.ray = &ray;
    }
    RTCRayHit rayHit{};
    rayHit.ray.org_x = ray.origin.x;
    rayHit.ray.org_y = ray.origin.y;
    rayHit.ray.org_z = ray.origin.z;
    rayHit.ray.dir_x = ray.direction.x;
    rayHit.ray.dir_y = ray.direction.y;
    rayHit.ray.dir_z = ray.direction.z;
    rayHit.ray.tnear = ray.tMin;
    rayHit.ray.tfar = ray.tMax;
    rayHit.ray.mask = ~0u;
    rayHit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(embree_->scene, &skip.context, &rayHit);
    if (rayHit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    SurfaceHit hit;
    hit.t = rayHit.ray.tfar;
    hit.shape = rayHit.hit.geomID;
    hit.triangle = rayHit.hit.primID;
    const TriangleMesh& mesh = shapes_[hit.shape].mesh;
    const auto& tri = mesh.triangles[hit.triangle];
    const float u = rayHit.hit.u, v = rayHit.hit.v;
    hit.position = mesh.positions[tri[0]] * (1 - u - v) + mesh.positions[tri[1]] * u + mesh.positions[tri[2]] * v;
    float scale = 0.0f;
    for (int k = 0; k < 3; ++k) {
        const Vec3& q = mesh.positions[tri[k]];
        scale = std::max({scale, std::abs(q.x), std::abs(q.y), std::abs(q.z)});
    }
    hit.scale = std::max(scale, 1e-30f);
    hit.geometricNormal = mesh.geometricNormal(hit.triangle);
    hit.shadingNormal = mesh.shadingNormal(hit.triangle, u, v);
    hit.uv = mesh.texcoord(hit.triangle, u, v);
    if (hit.shadingNormal.dot(hit.geometricNormal) < 0.0f) hit.shadingNormal = -hit.shadingNormal;
    return hit;
}

Vec2 Scene::texcoordOnPlane(const SurfaceHit& hit, const Vec3& point) const {
    const TriangleMesh& mesh = shapes_[hit.shape].mesh;
    const auto& tri = mesh.triangles[hit.triangle];
    // Barycentrics (u, v) of the projection: least squares of point - p0 = u e1 + v e2.
    const Imath::V3d p0(mesh.positions[tri[0]]);
    const Imath::V3d e1 = Imath::V3d(mesh.positions[tri[1]]) - p0, e2 = Imath::V3d(mesh.positions[tri[2]]) - p0;
    const Imath::V3d w = Imath::V3d(point) - p0;
    const double d11 = e1.dot(e1), d12 = e1.dot(e2), d22 = e2.dot(e2);
    const double determinant = d11 * d22 - d12 * d12;
    if (!(determinant > 1e-12 * d11 * d22)) return hit.uv;
    const double b1 = w.dot(e1), b2 = w.dot(e2);
    const double u = (d22 * b1 - d12 * b2) / determinant, v = (d11 * b2 - d12 * b1) / determinant;
    return mesh.texcoord(hit.triangle, float(u), float(v));
}

bool Scene::occluded(const Ray& ray) const {
    if (shapes_.empty()) return false;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay r{};
    r.org_x = ray.origin.x;
    r.org_y = ray.origin.y;
    r.org_z = ray.origin.z;
    r.dir_x = ray.direction.x;
    r.dir_y = ray.direction.y;
    r.dir_z = ray.direction.z;
    r.tnear = ray.tMin;
    r.tfar = ray.tMax;
    r.mask = ~0u;
    rtcOccluded1(embree_->scene, &context, &r);
    return r.tfar < 0.0f;
}

Vec3 Scene::offsetOrigin(const SurfaceHit& hit, const Vec3& direction) {
    const Vec3& p = hit.position;
    const float scale = hit.scale;
    const float side = direction.dot(hit.geometricNormal) >= 0.0f ? 1.0f : -1.0f;
    return p + hit.geometricNormal * (side * 1e-4f * scale);
}

void Scene::continuePast(Ray& ray, const SurfaceHit& hit) {
    const float scale = hit.scale;
    // Grazing hits widen the window only so far.
    const float cosine = std::max(std::abs(ray.direction.dot(hit.geometricNormal)), 0.1f);
    // Float noise around the crossing: a surface coinciding with the one crossed
    // (an opaque wall flush with a medium's boundary) is still found, and the
    // crossed triangle is ignored until past it (mediumAfter makes a repeated
    // crossing, e.g. of the neighbour on a shared edge, harmless).
    const float noise = 1e-5f * scale / cosine;
    // Coinciding boundaries (two media sharing a face) or a shared edge: keep skipping
    // everything crossed at this spot, or the ray would bounce between them.
    if (ray.skipCount > 0 && hit.t < ray.skipUntil && ray.skipCount < Ray::kMaxSkipped) {
        ray.skip[ray.skipCount++] = {hit.shape, hit.triangle};
    } else {
        ray.skip[0] = {hit.shape, hit.triangle};
        ray.skipCount = 1;
    }
    ray.tMin = std::max(0.0f, hit.t - noise);
    ray.skipUntil = hit.t + noise;
}

int Scene::mediumAfter(const SurfaceHit& hit, const Vec3& direction, int currentMedium) const {
    const SceneShape& shape = shapes_[hit.shape];
    if (!shape.changesMedium) return currentMedium;
    if (direction.dot(hit.geometricNormal) < 0.0f) return shape.interiorMedium;  // entering
    // Leaving: only from its own interior. A ray already in another medium crossed a
    // coinciding boundary first (or crosses this one twice at a shared edge): keep it.
    return currentMedium == shape.interiorMedium ? shape.exteriorMedium : currentMedium;
}

int Scene::mediumAt(const Vec3& point) const {
    int medium = description_.sensor.medium;
    const Vec3 from = camera_.position();
    const Vec3 d = point - from;
    const float distance = d.length();
    if (!(distance > 0.0f)) return medium;
    Ray ray{from, d / distance, distance};
    for (int crossings = 0; crossings < 4096; ++crossings) {
        const auto hit = intersect(ray);
        if (!hit) return medium;
        medium = mediumAfter(*hit, ray.direction, medium);
        continuePast(ray, *hit);
    }
    return medium;
}

bool Scene::visible(const Vec3& from, const Vec3& to) const {
    const Vec3 d = to - from;
    const float distance = d.length();
    if (!(distance > 0.0f)) return true;
    return !occluded(Ray{from, d / distance, distance * (1.0f - 1e-4f)});
}

Rgb Scene::transmittance(const Vec3& from, const Vec3& to, int medium) const {
    const Vec3 d = to - from;
    const float distance = d.length();
    if (!(distance > 0.0f)) return Rgb(1.0f);
    if (!hasNullSurfaces_) {
        if (!visible(from, to)) return Rgb(0.0f);
        return medium >= 0 ? media_[medium].transmittance(distance) : Rgb(1.0f);
    }
    // Stop short of the target so that an area light's own surface does not occlude.
    Ray ray{from, d / distance, distance * (1.0f - 1e-4f)};
    Rgb result(1.0f);
    float segmentStart = 0.0f;
    // Walk the one ray through null boundaries (bounded against degenerate meshes).
    for (int crossings = 0; crossings < 256; ++crossings) {
        const auto hit = intersect(ray);
        const float segmentEnd = hit ? hit->t : distance;
        if (medium >= 0) result *= media_[medium].transmittance(segmentEnd - segmentStart);
        if (!hit) return result;
        if (!shapes_[hit->shape].bsdf.isNull()) return Rgb(0.0f);
        medium = mediumAfter(*hit, ray.direction, medium);
        segmentStart = hit->t;
        continuePast(ray, *hit);
    }
    return Rgb(0.0f);
}

}  // namespace vrl
