#include "render/shape_mesh.h"

#include <tiny_obj_loader.h>

#include <cmath>
#include <filesystem>

namespace vrl {

namespace {

TriangleMesh makeRectangle() {
    TriangleMesh m;
    m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    return m;
}

TriangleMesh makeCube() {
    TriangleMesh m;
    // Each face: a corner, two edge vectors whose cross product points outwards.
    for (int axis = 0; axis < 3; ++axis) {
        for (float side : {-1.0f, 1.0f}) {
            Vec3 n(0.0f), a(0.0f), b(0.0f);
            n[axis] = side;
            a[(axis + 1) % 3] = 1.0f;
            b[(axis + 2) % 3] = 1.0f;
            if (side < 0) std::swap(a, b);
            const auto base = static_cast<uint32_t>(m.positions.size());
            m.positions.push_back(n - a - b);
            m.positions.push_back(n + a - b);
            m.positions.push_back(n + a + b);
            m.positions.push_back(n - a + b);
            m.triangles.push_back({base, base + 1, base + 2});
            m.triangles.push_back({base, base + 2, base + 3});
        }
    }
    return m;
}

TriangleMesh makeDisk() {
    TriangleMesh m;
    const int wedges = 2 * kCurvedShapeSegments;
    m.positions.push_back({0, 0, 0});
    for (int i = 0; i < wedges; ++i) {
        const float phi = 2.0f * kPi * float(i) / float(wedges);
        m.positions.push_back({std::cos(phi), std::sin(phi), 0});
    }
    for (uint32_t i = 0; i < uint32_t(wedges); ++i) m.triangles.push_back({0, 1 + i, 1 + (i + 1) % wedges});
    return m;
}

TriangleMesh makeSphere(const Vec3& center, float radius) {
    TriangleMesh m;
    const int rings = kCurvedShapeSegments, sectors = 2 * kCurvedShapeSegments;
    for (int r = 0; r <= rings; ++r) {
        const float theta = kPi * float(r) / float(rings);
        for (int s = 0; s <= sectors; ++s) {
            const float phi = 2.0f * kPi * float(s) / float(sectors);
            const Vec3 n = sphericalDirection(std::sin(theta), std::cos(theta), phi);
            m.positions.push_back(center + n * radius);
            m.normals.push_back(n);
        }
    }
    const auto index = [&](int r, int s) { return uint32_t(r * (sectors + 1) + s); };
    for (int r = 0; r < rings; ++r) {
        for (int s = 0; s < sectors; ++s) {
            // Counter-clockwise seen from outside (theta grows downwards, phi anticlockwise).
            if (r > 0) m.triangles.push_back({index(r, s), index(r + 1, s), index(r, s + 1)});
            if (r < rings - 1) m.triangles.push_back({index(r, s + 1), index(r + 1, s), index(r + 1, s + 1)});
        }
    }
    return m;
}

TriangleMesh loadObj(const ShapeDescription& shape) {
    if (!std::filesystem::exists(shape.filename))
        throw SceneError(shape.where, "mesh file '" + shape.filename.string() + "' does not exist");
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(shape.filename.string(), config))
        throw SceneError(shape.where, "cannot read mesh '" + shape.filename.string() + "': " + reader.Error());
    const auto& attrib = reader.GetAttrib();
    const bool useNormals = !shape.faceNormals && !attrib.normals.empty();
    TriangleMesh m;
    // Vertices are emitted per face corner (no welding): simple and exact.
    for (const auto& objShape : reader.GetShapes()) {
        const auto& idx = objShape.mesh.indices;
        for (size_t f = 0; f + 2 < idx.size(); f += 3) {
            bool haveNormals = useNormals;
            for (int k = 0; k < 3; ++k) haveNormals = haveNormals && idx[f + k].normal_index >= 0;
            const auto base = static_cast<uint32_t>(m.positions.size());
            for (int k = 0; k < 3; ++k) {
                const int vi = idx[f + k].vertex_index;
                if (vi < 0 || size_t(3 * vi + 2) >= attrib.vertices.size())
                    throw SceneError(shape.where, "mesh '" + shape.filename.string() + "' has an invalid vertex index");
                m.positions.push_back({attrib.vertices[3 * vi], attrib.vertices[3 * vi + 1], attrib.vertices[3 * vi + 2]});
            }
            if (useNormals) {
                for (int k = 0; k < 3; ++k) {
                    const int ni = idx[f + k].normal_index;
                    m.normals.push_back(haveNormals ? Vec3(attrib.normals[3 * ni], attrib.normals[3 * ni + 1],
                                                           attrib.normals[3 * ni + 2])
                                                    : Vec3(0.0f));
                }
            }
            m.triangles.push_back({base, base + 1, base + 2});
        }
    }
    if (m.triangles.empty())
        throw SceneError(shape.where, "mesh '" + shape.filename.string() + "' contains no triangles");
    return m;
}

}  // namespace

TriangleMesh buildShapeMesh(const ShapeDescription& shape) {
    TriangleMesh m;
    switch (shape.kind) {
        case ShapeDescription::Kind::Rectangle: m = makeRectangle(); break;
        case ShapeDescription::Kind::Cube: m = makeCube(); break;
        case ShapeDescription::Kind::Disk: m = makeDisk(); break;
        case ShapeDescription::Kind::Sphere: m = makeSphere(shape.center, shape.radius); break;
        case ShapeDescription::Kind::Obj: m = loadObj(shape); break;
    }
    const bool mirrored = shape.toWorld.flipsHandedness();
    for (auto& p : m.positions) p = shape.toWorld.applyPoint(p);
    for (auto& n : m.normals) {
        if (n.length2() > 0) n = shape.toWorld.applyNormal(n).normalized();
    }
    // A mirroring transform reverses the winding; restore the outward orientation.
    if (mirrored != shape.flipNormals) {
        for (auto& t : m.triangles) std::swap(t[1], t[2]);
    }
    if (shape.flipNormals) {
        for (auto& n : m.normals) n = -n;
    }
    // Degenerate vertex normals (zero or NaN) fall back to flat shading for the whole mesh.
    for (const auto& n : m.normals) {
        if (!(n.length2() > 0.5f)) {
            m.normals.clear();
            break;
        }
    }
    for (const auto& p : m.positions) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw SceneError(shape.where, "shape has non-finite vertex positions after its toWorld transform");
    }
    return m;
}

}  // namespace vrl
