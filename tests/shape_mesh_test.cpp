// Tests of buildShapeMesh: the area of every tessellated shape against its
// closed form (or the exact area of the inscribed polygon / polyhedron), the
// outward orientation of triangles and vertex normals under flipNormals and
// mirroring transforms, watertightness of closed shapes, and mesh-file errors.
#include "render/shape_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace vrl {
namespace {

using Kind = ShapeDescription::Kind;

const std::filesystem::path kIcosahedron =
    std::filesystem::path(VRL_TEST_DATA_DIR) / "../scenes/meshes/icosahedron.obj";

ShapeDescription shape(Kind kind, const Transform& toWorld = {}) {
    ShapeDescription s;
    s.kind = kind;
    s.toWorld = toWorld;
    if (kind == Kind::Obj) s.filename = kIcosahedron;
    return s;
}

double totalArea(const TriangleMesh& m) {
    double area = 0.0;
    for (size_t i = 0; i < m.triangles.size(); ++i) area += m.triangleArea(i);
    return area;
}

Vec3 centroid(const TriangleMesh& m, size_t i) {
    const auto& t = m.triangles[i];
    return (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]) / 3.0f;
}

// Smallest cosine between a triangle's geometric normal and the direction from
// `centre` to the triangle's centroid (negative: some triangle faces inwards).
float minOutwardCosine(const TriangleMesh& m, const Vec3& centre) {
    float result = 1.0f;
    for (size_t i = 0; i < m.triangles.size(); ++i)
        result = std::min(result, m.geometricNormal(i).dot((centroid(m, i) - centre).normalized()));
    return result;
}

float maxOutwardCosine(const TriangleMesh& m, const Vec3& centre) {
    float result = -1.0f;
    for (size_t i = 0; i < m.triangles.size(); ++i)
        result = std::max(result, m.geometricNormal(i).dot((centroid(m, i) - centre).normalized()));
    return result;
}

// Undirected edges (after welding positions closer than 1e-5) -> the number of
// triangles using them; also counts directed edges seen twice (inconsistent winding).
struct EdgeCensus {
    std::map<std::pair<size_t, size_t>, int> uses;
    int repeatedDirectedEdges = 0;
    int degenerateTriangles = 0;
};

EdgeCensus censusOfEdges(const TriangleMesh& m) {
    std::vector<size_t> weld(m.positions.size());
    std::vector<size_t> representatives;
    for (size_t v = 0; v < m.positions.size(); ++v) {
        weld[v] = v;
        for (size_t r : representatives) {
            if ((m.positions[v] - m.positions[r]).length() < 1e-5f) {
                weld[v] = r;
                break;
            }
        }
        if (weld[v] == v) representatives.push_back(v);
    }
    EdgeCensus census;
    std::map<std::pair<size_t, size_t>, int> directed;
    for (const auto& t : m.triangles) {
        const size_t a = weld[t[0]], b = weld[t[1]], c = weld[t[2]];
        if (a == b || b == c || a == c) ++census.degenerateTriangles;
        for (const auto& [from, to] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
            if (++directed[{from, to}] == 2) ++census.repeatedDirectedEdges;
            ++census.uses[{std::min(from, to), std::max(from, to)}];
        }
    }
    return census;
}

void expectWatertight(const TriangleMesh& m, size_t expectedEdges) {
    const EdgeCensus census = censusOfEdges(m);
    EXPECT_EQ(census.degenerateTriangles, 0);
    EXPECT_EQ(census.repeatedDirectedEdges, 0) << "neighbouring triangles wound inconsistently";
    EXPECT_EQ(census.uses.size(), expectedEdges);
    int badEdges = 0;
    for (const auto& [edge, count] : census.uses) badEdges += count != 2;
    EXPECT_EQ(badEdges, 0) << "edges not shared by exactly two triangles";
}

// Area of the UV sphere's inscribed polyhedron (rings x sectors planar isosceles
// trapezoids, triangles at the poles), computed from the construction in double.
double inscribedUvSphereArea(double radius, int rings, int sectors) {
    const double halfPhi = M_PI / sectors;
    double band = 0.0;
    for (int r = 0; r < rings; ++r) {
        const double t0 = M_PI * r / rings, t1 = M_PI * (r + 1) / rings;
        const double a = 2 * std::sin(t0) * std::sin(halfPhi), b = 2 * std::sin(t1) * std::sin(halfPhi);
        const double h = std::hypot(std::cos(halfPhi) * (std::sin(t1) - std::sin(t0)), std::cos(t1) - std::cos(t0));
        band += 0.5 * (a + b) * h;
    }
    return sectors * band * radius * radius;
}

TEST(ShapeMeshTest, RectangleAndCubeAreas) {
    EXPECT_NEAR(totalArea(buildShapeMesh(shape(Kind::Rectangle))), 4.0, 1e-6);
    EXPECT_EQ(buildShapeMesh(shape(Kind::Cube)).triangles.size(), 12u);
    EXPECT_NEAR(totalArea(buildShapeMesh(shape(Kind::Cube))), 24.0, 1e-6);
    EXPECT_NEAR(totalArea(buildShapeMesh(shape(Kind::Cube, Transform::scale(Vec3(1.5f))))), 24.0 * 2.25, 1e-5);
    // Non-uniform: 2 faces each of 2sx x 2sy, 2sy x 2sz, 2sx x 2sz.
    const auto box = buildShapeMesh(shape(Kind::Cube, Transform::scale(Vec3(2.0f, 3.0f, 0.5f))));
    EXPECT_NEAR(totalArea(box), 8.0 * (2 * 3 + 3 * 0.5 + 2 * 0.5), 1e-5);
}

TEST(ShapeMeshTest, DiskIsTheInscribedRegularPolygon) {
    const int n = 2 * kCurvedShapeSegments;
    const auto disk = buildShapeMesh(shape(Kind::Disk));
    ASSERT_EQ(disk.triangles.size(), size_t(n));
    const double polygon = 0.5 * n * std::sin(2 * M_PI / n);
    EXPECT_NEAR(totalArea(disk), polygon, 1e-5 * polygon);
    // The polygon misses (2 pi / n)^2 / 6 = 0.07% of pi for n = 96.
    EXPECT_LT(totalArea(disk), M_PI);
    EXPECT_NEAR(totalArea(disk), M_PI, 1e-3 * M_PI);
    const auto scaled = buildShapeMesh(shape(Kind::Disk, Transform::scale(Vec3(2.0f, 2.0f, 1.0f))));
    EXPECT_NEAR(totalArea(scaled), 4 * polygon, 4e-5 * polygon);
}

TEST(ShapeMeshTest, SphereIsTheInscribedUvPolyhedron) {
    auto s = shape(Kind::Sphere);
    s.center = Vec3(1.0f, -2.0f, 0.5f);
    s.radius = 0.7f;
    const auto sphere = buildShapeMesh(s);
    const int rings = kCurvedShapeSegments, sectors = 2 * kCurvedShapeSegments;
    EXPECT_EQ(sphere.triangles.size(), size_t(2 * sectors * (rings - 1)));
    const double inscribed = inscribedUvSphereArea(0.7, rings, sectors);
    EXPECT_NEAR(totalArea(sphere), inscribed, 1e-5 * inscribed);
    // Inscribed, so below 4 pi r^2; with 48 rings the deficit is ~0.14%, under 0.5%.
    const double exact = 4 * M_PI * 0.7 * 0.7;
    EXPECT_LT(totalArea(sphere), exact);
    EXPECT_GT(totalArea(sphere), 0.995 * exact);
}

TEST(ShapeMeshTest, IcosahedronObjHasTheClosedFormArea) {
    const auto ico = buildShapeMesh(shape(Kind::Obj));
    ASSERT_EQ(ico.triangles.size(), 20u);
    // Unit circumradius: edge a = 4 / sqrt(10 + 2 sqrt 5), area 5 sqrt(3) a^2 = 9.5745.
    const double a2 = 16.0 / (10.0 + 2.0 * std::sqrt(5.0));
    const double area = 5.0 * std::sqrt(3.0) * a2;
    EXPECT_NEAR(totalArea(ico), area, 1e-5 * area);  // the file's vertices have 6 decimals
    EXPECT_NEAR(totalArea(buildShapeMesh(shape(Kind::Obj, Transform::scale(Vec3(0.45f))))), 0.45 * 0.45 * area,
                1e-5 * area);
}

TEST(ShapeMeshTest, ClosedShapesFaceOutwards) {
    // Face normals against the centroid direction: cube >= 1/sqrt(1 + 2/9) = 0.905
    // (triangle centroids sit off the face centres), icosahedron exactly radial,
    // sphere nearly radial.
    EXPECT_GT(minOutwardCosine(buildShapeMesh(shape(Kind::Cube)), Vec3(0.0f)), 0.90f);
    EXPECT_GT(minOutwardCosine(buildShapeMesh(shape(Kind::Obj)), Vec3(0.0f)), 0.9999f);
    auto s = shape(Kind::Sphere);
    s.center = Vec3(0.0f, 3.0f, 0.0f);
    s.radius = 2.0f;
    EXPECT_GT(minOutwardCosine(buildShapeMesh(s), s.center), 0.99f);
    const Transform moved = Transform::rotate(Vec3(1, 2, 3), 40.0f).then(Transform::translate(Vec3(5, -1, 2)));
    EXPECT_GT(minOutwardCosine(buildShapeMesh(shape(Kind::Cube, moved)), Vec3(5, -1, 2)), 0.90f);
}

TEST(ShapeMeshTest, FlatShapesFacePlusZ) {
    // Untransformed: +z. Mirrored through their plane (z -> -z) or turned over: -z,
    // as the inverse-transpose normal of Mitsuba's toWorld says.
    const std::pair<Transform, float> cases[] = {{Transform(), 1.0f},
                                                 {Transform::scale(Vec3(1, 1, -1)), -1.0f},
                                                 {Transform::rotate(Vec3(1, 0, 0), 180.0f), -1.0f}};
    for (const Kind kind : {Kind::Rectangle, Kind::Disk}) {
        for (const auto& [toWorld, z] : cases) {
            const auto m = buildShapeMesh(shape(kind, toWorld));
            for (size_t i = 0; i < m.triangles.size(); ++i)
                ASSERT_NEAR(m.geometricNormal(i).z, z, 1e-6f) << "kind " << int(kind) << ", triangle " << i;
        }
    }
}

TEST(ShapeMeshTest, FlipNormalsReversesEveryTriangle) {
    for (const Kind kind : {Kind::Rectangle, Kind::Cube, Kind::Disk, Kind::Sphere, Kind::Obj}) {
        auto s = shape(kind);
        const auto front = buildShapeMesh(s);
        s.flipNormals = true;
        const auto back = buildShapeMesh(s);
        ASSERT_EQ(front.triangles.size(), back.triangles.size());
        for (size_t i = 0; i < front.triangles.size(); ++i) {
            const Vec3 sum = front.geometricNormal(i) + back.geometricNormal(i);
            ASSERT_LT(sum.length(), 1e-6f) << "kind " << int(kind) << ", triangle " << i;
        }
    }
    auto cube = shape(Kind::Cube);
    cube.flipNormals = true;
    EXPECT_LT(maxOutwardCosine(buildShapeMesh(cube), Vec3(0.0f)), -0.90f);
}

TEST(ShapeMeshTest, MirroringTransformKeepsClosedShapesOutward) {
    const Transform mirror = Transform::scale(Vec3(-1, 1, 1)).then(Transform::translate(Vec3(3, 0, 0)));
    ASSERT_TRUE(mirror.flipsHandedness());
    EXPECT_GT(minOutwardCosine(buildShapeMesh(shape(Kind::Cube, mirror)), Vec3(3, 0, 0)), 0.90f);
    EXPECT_GT(minOutwardCosine(buildShapeMesh(shape(Kind::Obj, mirror)), Vec3(3, 0, 0)), 0.9999f);
    auto sphere = shape(Kind::Sphere, mirror);
    sphere.center = Vec3(1, 0, 0);  // world centre (2, 0, 0)
    EXPECT_GT(minOutwardCosine(buildShapeMesh(sphere), Vec3(2, 0, 0)), 0.99f);
    // Mirrored and flipped: inwards.
    auto flipped = shape(Kind::Obj, mirror);
    flipped.flipNormals = true;
    EXPECT_LT(maxOutwardCosine(buildShapeMesh(flipped), Vec3(3, 0, 0)), -0.9999f);
    // A mirrored rectangle still faces +z (the mirror is in its plane).
    const auto rect = buildShapeMesh(shape(Kind::Rectangle, Transform::scale(Vec3(-1, 1, 1))));
    for (size_t i = 0; i < rect.triangles.size(); ++i) EXPECT_NEAR(rect.geometricNormal(i).z, 1.0f, 1e-6f);
}

// Vertex normals are radial and on the same side as the face normals.
void expectSphereVertexNormals(const ShapeDescription& s, const Vec3& worldCentre, float side) {
    const auto m = buildShapeMesh(s);
    ASSERT_EQ(m.normals.size(), m.positions.size());
    for (size_t v = 0; v < m.positions.size(); ++v) {
        const Vec3 radial = (m.positions[v] - worldCentre) / s.radius;
        ASSERT_LT((m.normals[v] - radial * side).length(), 1e-5f) << "vertex " << v;
    }
    for (size_t i = 0; i < m.triangles.size(); ++i)
        for (const uint32_t v : m.triangles[i]) ASSERT_GT(m.normals[v].dot(m.geometricNormal(i)), 0.99f);
}

TEST(ShapeMeshTest, SphereVertexNormalsAgreeWithGeometricNormals) {
    auto s = shape(Kind::Sphere);
    s.center = Vec3(0.5f, 0.0f, -1.0f);
    s.radius = 1.5f;
    expectSphereVertexNormals(s, s.center, 1.0f);
    s.flipNormals = true;
    expectSphereVertexNormals(s, s.center, -1.0f);
    s.flipNormals = false;
    s.toWorld = Transform::scale(Vec3(-1, 1, 1));
    expectSphereVertexNormals(s, Vec3(-0.5f, 0.0f, -1.0f), 1.0f);
}

TEST(ShapeMeshTest, ClosedShapesAreWatertight) {
    expectWatertight(buildShapeMesh(shape(Kind::Cube)), 18);
    expectWatertight(buildShapeMesh(shape(Kind::Obj)), 30);
    const int rings = kCurvedShapeSegments, sectors = 2 * kCurvedShapeSegments;
    // Euler: V = sectors (rings - 1) + 2, F = 2 sectors (rings - 1), E = V + F - 2.
    expectWatertight(buildShapeMesh(shape(Kind::Sphere)), size_t(3 * sectors * (rings - 1)));
    auto flipped = shape(Kind::Sphere, Transform::scale(Vec3(-2, 1, 1)));
    flipped.flipNormals = true;
    expectWatertight(buildShapeMesh(flipped), size_t(3 * sectors * (rings - 1)));
}

void expectSceneErrorNaming(const ShapeDescription& s, const std::string& name) {
    try {
        buildShapeMesh(s);
        FAIL() << "expected a SceneError for " << s.filename;
    } catch (const SceneError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(name), std::string::npos) << message;
        EXPECT_NE(message.find("room.xml:12"), std::string::npos) << message;
    }
}

std::filesystem::path scratchFile(const std::string& name, const std::string& contents) {
    const auto dir = std::filesystem::path(testing::TempDir()) / "shape_mesh_test";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / name) << contents;
    return dir / name;
}

TEST(ShapeMeshTest, MissingAndEmptyObjFilesAreSceneErrors) {
    auto s = shape(Kind::Obj);
    s.where = {"room.xml", 12, "<shape type=\"obj\">"};
    s.filename = std::filesystem::path(testing::TempDir()) / "no-such-mesh.obj";
    expectSceneErrorNaming(s, "no-such-mesh.obj");
    s.filename = scratchFile("empty-mesh.obj", "");
    expectSceneErrorNaming(s, "empty-mesh.obj");
    s.filename = scratchFile("vertices-only.obj", "# no faces\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    expectSceneErrorNaming(s, "vertices-only.obj");
    s.filename = scratchFile("placeholder", "").parent_path();  // a directory, not a file
    expectSceneErrorNaming(s, "shape_mesh_test");
}

}  // namespace
}  // namespace vrl
