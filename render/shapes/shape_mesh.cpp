#include "render/shapes/shape_mesh.h"

#include "render/shapes/serialized_mesh.h"

#include <tiny_obj_loader.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace vrl {

namespace {

// Mitsuba's rectangle uv: (-1,-1) -> (0,0), (1,-1) -> (1,0), (1,1) -> (1,1), (-1,1) -> (0,1).
TriangleMesh makeRectangle() {
    TriangleMesh m;
    m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    m.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    return m;
}

// Mitsuba 0.5's cube (src/shapes/cube.cpp): per face four corners with their uv, every face
// mapped onto [0,1]^2, triangles (0,1,2) and (3,0,2) wound outwards.
struct CubeCorner {
    float x, y, z, u, v;
};
constexpr CubeCorner kCubeFaces[6][4] = {
    {{1, -1, -1, 0, 1}, {1, -1, 1, 1, 1}, {-1, -1, 1, 1, 0}, {-1, -1, -1, 0, 0}},  // -y
    {{1, 1, -1, 0, 1}, {-1, 1, -1, 1, 1}, {-1, 1, 1, 1, 0}, {1, 1, 1, 0, 0}},      // +y
    {{1, -1, -1, 0, 1}, {1, 1, -1, 1, 1}, {1, 1, 1, 1, 0}, {1, -1, 1, 0, 0}},      // +x
    {{1, -1, 1, 0, 1}, {1, 1, 1, 1, 1}, {-1, 1, 1, 1, 0}, {-1, -1, 1, 0, 0}},      // +z
    {{-1, -1, 1, 0, 1}, {-1, 1, 1, 1, 1}, {-1, 1, -1, 1, 0}, {-1, -1, -1, 0, 0}},  // -x
    {{1, 1, -1, 0, 1}, {1, -1, -1, 1, 1}, {-1, -1, -1, 1, 0}, {-1, 1, -1, 0, 0}},  // -z
};

TriangleMesh makeCube() {
    TriangleMesh m;
    for (const auto& face : kCubeFaces) {
        const auto base = static_cast<uint32_t>(m.positions.size());
        for (const CubeCorner& c : face) {
            m.positions.push_back({c.x, c.y, c.z});
            m.texcoords.push_back({c.u, c.v});
        }
        m.triangles.push_back({base, base + 1, base + 2});
        m.triangles.push_back({base + 3, base, base + 2});
    }
    return m;
}

// Mitsuba's disk uv is (r, phi / 2 pi). Rim vertex k sits at phi_k = 2 pi k / n with uv
// (1, k / n); the rim vertex at 2 pi repeats the one at 0 with v = 1 (the seam). Each wedge
// has its own centre vertex, uv (0, v at the wedge's middle angle).
TriangleMesh makeDisk() {
    TriangleMesh m;
    const int wedges = 2 * kCurvedShapeSegments;
    for (int k = 0; k <= wedges; ++k) {
        const float phi = 2.0f * kPi * float(k % wedges) / float(wedges);
        m.positions.push_back({std::cos(phi), std::sin(phi), 0});
        m.texcoords.push_back({1.0f, float(k) / float(wedges)});
    }
    for (int i = 0; i < wedges; ++i) {
        m.positions.push_back({0, 0, 0});
        m.texcoords.push_back({0.0f, (float(i) + 0.5f) / float(wedges)});
    }
    const auto rim = [](int k) { return uint32_t(k); };
    const auto centre = [&](int i) { return uint32_t(wedges + 1 + i); };
    for (int i = 0; i < wedges; ++i) m.triangles.push_back({centre(i), rim(i), rim(i + 1)});
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
            // Mitsuba's sphere uv: (phi / 2 pi, theta / pi), theta from +z.
            m.texcoords.push_back({float(s) / float(sectors), float(r) / float(rings)});
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

// OBJ through tinyobjloader, which triangulates quads (along the shorter diagonal) and
// larger polygons (ear clipping) and accepts v, v/vt, v//vn and v/vt/vn corners mixed in one
// file. Vertices are emitted per triangle corner (no welding): simple and exact.
TriangleMesh loadObj(const ShapeDescription& shape) {
    const std::string file = shape.filename.string();
    if (!std::filesystem::exists(shape.filename))
        throw SceneError(shape.where, "mesh file '" + file + "' does not exist");
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(file, config))
        throw SceneError(shape.where, "cannot read mesh '" + file + "': " + reader.Error());
    if (reader.Warning().find("invalid vertex index") != std::string::npos)
        throw SceneError(shape.where, "mesh '" + file + "' has an invalid vertex index");
    const auto& attrib = reader.GetAttrib();
    const auto invalid = [&](const char* what) {
        return SceneError(shape.where, "mesh '" + file + "' has an invalid " + what + " index");
    };
    const bool useNormals = !shape.faceNormals && !attrib.normals.empty();
    // Texture coordinates when any corner has one; corners without get (0, 0).
    bool useTexcoords = false;
    for (const auto& objShape : reader.GetShapes())
        for (const auto& index : objShape.mesh.indices) useTexcoords = useTexcoords || index.texcoord_index >= 0;
    TriangleMesh m;
    for (const auto& objShape : reader.GetShapes()) {
        const auto& idx = objShape.mesh.indices;
        for (size_t f = 0; f + 2 < idx.size(); f += 3) {
            bool haveNormals = useNormals;
            for (int k = 0; k < 3; ++k) haveNormals = haveNormals && idx[f + k].normal_index >= 0;
            const auto base = static_cast<uint32_t>(m.positions.size());
            for (int k = 0; k < 3; ++k) {
                const tinyobj::index_t& corner = idx[f + k];
                const int vi = corner.vertex_index;
                // In size_t: 3 * vi overflows int for indices above 715 million (fuzzing found it).
                if (vi < 0 || 3 * size_t(vi) + 2 >= attrib.vertices.size()) throw invalid("vertex");
                m.positions.push_back({attrib.vertices[3 * size_t(vi)], attrib.vertices[3 * size_t(vi) + 1], attrib.vertices[3 * size_t(vi) + 2]});
                if (useNormals) {
                    const int ni = corner.normal_index;
                    if (haveNormals && 3 * size_t(ni) + 2 >= attrib.normals.size()) throw invalid("normal");
                    m.normals.push_back(haveNormals ? Vec3(attrib.normals[3 * size_t(ni)], attrib.normals[3 * size_t(ni) + 1],
                                                           attrib.normals[3 * size_t(ni) + 2])
                                                    : Vec3(0.0f));
                }
                if (useTexcoords) {
                    const int ti = corner.texcoord_index;
                    if (ti >= 0 && 2 * size_t(ti) + 1 >= attrib.texcoords.size()) throw invalid("texture coordinate");
                    m.texcoords.push_back(ti >= 0 ? Vec2(attrib.texcoords[2 * size_t(ti)], attrib.texcoords[2 * size_t(ti) + 1])
                                                  : Vec2(0.0f));
                }
            }
            m.triangles.push_back({base, base + 1, base + 2});
        }
    }
    if (m.triangles.empty())
        throw SceneError(shape.where, "mesh '" + file + "' contains no triangles");
    return m;
}

// Shape shapeIndex of a Mitsuba .serialized file, in object space.
TriangleMesh loadSerialized(const ShapeDescription& shape) {
    TriangleMesh m;
    try {
        m = loadSerializedMesh(shape.filename, shape.shapeIndex);
    } catch (const std::runtime_error& e) {
        throw SceneError(shape.where, std::string("cannot load serialized mesh: ") + e.what());
    }
    if (shape.faceNormals) m.normals.clear();
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
        case ShapeDescription::Kind::Serialized: m = loadSerialized(shape); break;
    }
    // Mitsuba's uv put v = 0 at the image's top row; Texture's at the bottom row (OBJ's
    // convention, which Mitsuba's default flipTexCoords undoes).
    if (shape.kind != ShapeDescription::Kind::Obj || !shape.flipTexCoords) {
        for (auto& uv : m.texcoords) uv.y = 1.0f - uv.y;
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
