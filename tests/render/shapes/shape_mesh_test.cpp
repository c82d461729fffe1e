// Tests of buildShapeMesh: the area of every tessellated shape against its
// closed form (or the exact area of the inscribed polygon / polyhedron), the
// outward orientation of triangles and vertex normals under flipNormals and
// mirroring transforms, watertightness of closed shapes, Mitsuba's texture
// coordinates of the analytic shapes, OBJ quads, polygons, mixed face formats and
// vt, .serialized shapes (written here with zlib), and mesh-file errors.
#include "render/shapes/shape_mesh.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
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


// --- Texture coordinates of the analytic shapes (Mitsuba's parameterisations) ---
// Stored as (u, 1 - v): Mitsuba's v = 0 is an image's top row, Texture's the bottom row.

TEST(ShapeMeshTest, RectangleTexcoordsFollowMitsuba) {
    const auto m = buildShapeMesh(shape(Kind::Rectangle));
    ASSERT_EQ(m.texcoords.size(), m.positions.size());
    for (size_t v = 0; v < m.positions.size(); ++v)
        EXPECT_EQ(m.texcoords[v], Vec2((m.positions[v].x + 1) / 2, 1 - (m.positions[v].y + 1) / 2));
    // uv belongs to the object-space corner, whatever toWorld does (here a mirror).
    const auto mirrored = buildShapeMesh(shape(Kind::Rectangle, Transform::scale(Vec3(-2, 1, 1))));
    for (size_t v = 0; v < mirrored.positions.size(); ++v)
        EXPECT_EQ(mirrored.texcoords[v], Vec2((-mirrored.positions[v].x / 2 + 1) / 2, 1 - (mirrored.positions[v].y + 1) / 2));
    // Interpolated inside a triangle: the centre of the square, halfway from corner 0 to
    // corner 2 of triangle 0, maps to (0.5, 0.5).
    EXPECT_EQ(m.texcoord(0, 0.0f, 0.5f), Vec2(0.5f, 0.5f));
}

TEST(ShapeMeshTest, CubeTexcoordsMapEveryFaceOntoTheUnitSquare) {
    const auto m = buildShapeMesh(shape(Kind::Cube));
    ASSERT_EQ(m.texcoords.size(), 24u);
    for (size_t face = 0; face < 6; ++face) {
        std::map<std::pair<float, float>, int> corners;
        for (size_t k = 0; k < 4; ++k) ++corners[{m.texcoords[4 * face + k].x, m.texcoords[4 * face + k].y}];
        EXPECT_EQ(corners.size(), 4u) << "face " << face;
        for (const auto& [uv, count] : corners) {
            EXPECT_TRUE(uv.first == 0 || uv.first == 1);
            EXPECT_TRUE(uv.second == 0 || uv.second == 1);
        }
    }
    // Mitsuba's +z face: (1,-1,1) -> (0,1), (1,1,1) -> (1,1), (-1,1,1) -> (1,0), (-1,-1,1) -> (0,0).
    for (size_t v = 12; v < 16; ++v) {
        ASSERT_EQ(m.positions[v].z, 1.0f);
        EXPECT_EQ(m.texcoords[v], Vec2((m.positions[v].y + 1) / 2, 1 - (m.positions[v].x + 1) / 2)) << "vertex " << v;
    }
}

TEST(ShapeMeshTest, SphereTexcoordsArePhiAndTheta) {
    auto s = shape(Kind::Sphere);
    s.center = Vec3(1, 2, 3);
    s.radius = 2.0f;
    const auto m = buildShapeMesh(s);
    ASSERT_EQ(m.texcoords.size(), m.positions.size());
    for (size_t v = 0; v < m.positions.size(); ++v) {
        const Vec3 d = (m.positions[v] - s.center) / s.radius;
        const Vec2 uv = m.texcoords[v];
        EXPECT_NEAR(1 - uv.y, std::acos(std::clamp(d.z, -1.0f, 1.0f)) / M_PI, 1e-5) << "vertex " << v;
        if (std::hypot(d.x, d.y) < 1e-3f) continue;  // poles: phi undefined
        float phi = std::atan2(d.y, d.x);
        if (phi < 0) phi += 2 * float(M_PI);
        const float u = phi / (2 * float(M_PI));
        // The seam has vertices on both sides: u = 0 and u = 1.
        EXPECT_LT(std::min(std::abs(uv.x - u), std::abs(std::abs(uv.x - u) - 1.0f)), 1e-5f) << "vertex " << v;
    }
    // No triangle spans the seam: u varies by at most one sector within a triangle.
    for (size_t i = 0; i < m.triangles.size(); ++i) {
        const auto& t = m.triangles[i];
        float lo = 2, hi = -1;
        for (uint32_t v : t) lo = std::min(lo, m.texcoords[v].x), hi = std::max(hi, m.texcoords[v].x);
        ASSERT_LE(hi - lo, 1.0f / (2 * kCurvedShapeSegments) + 1e-6f) << "triangle " << i;
    }
}

TEST(ShapeMeshTest, DiskTexcoordsAreRadiusAndAngle) {
    const auto m = buildShapeMesh(shape(Kind::Disk));
    ASSERT_EQ(m.texcoords.size(), m.positions.size());
    for (size_t v = 0; v < m.positions.size(); ++v) {
        const Vec3& p = m.positions[v];
        const float r = std::hypot(p.x, p.y);
        EXPECT_NEAR(m.texcoords[v].x, r, 1e-6f);
        if (r < 0.5f) continue;
        float phi = std::atan2(p.y, p.x);
        if (phi < -1e-6f) phi += 2 * float(M_PI);
        const float v01 = 1 - m.texcoords[v].y;
        EXPECT_TRUE(std::abs(v01 - phi / (2 * float(M_PI))) < 1e-5f || (v01 == 1.0f && std::abs(phi) < 1e-5f))
            << "vertex " << v;
    }
    for (const auto& t : m.triangles) EXPECT_LE(std::abs(m.texcoords[t[2]].y - m.texcoords[t[1]].y), 0.011f);
}

// --- OBJ faces: quads, polygons, mixed formats, vt ---

double areaTowards(const TriangleMesh& m, const Vec3& direction) {
    double area = 0.0;
    for (size_t i = 0; i < m.triangles.size(); ++i) area += m.triangleArea(i) * m.geometricNormal(i).dot(direction);
    return area;
}

ShapeDescription objShape(const std::string& name, const std::string& contents) {
    auto s = shape(Kind::Obj);
    s.filename = scratchFile(name, contents);
    return s;
}

TEST(ShapeMeshTest, ObjQuadsAndPolygonsAreTriangulated) {
    // A 2 x 1 quad and an L-shaped (concave) hexagon of area 3, both facing +z.
    const auto m = buildShapeMesh(objShape("polygons.obj",
                                           "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\n"
                                           "v 0 0 1\nv 2 0 1\nv 2 1 1\nv 1 1 1\nv 1 2 1\nv 0 2 1\n"
                                           "f 1 2 3 4\nf 5 6 7 8 9 10\n"));
    ASSERT_EQ(m.triangles.size(), 2u + 4u);
    EXPECT_NEAR(totalArea(m), 2.0 + 3.0, 1e-6);
    EXPECT_NEAR(areaTowards(m, Vec3(0, 0, 1)), 5.0, 1e-6);  // every triangle faces +z
    EXPECT_TRUE(m.texcoords.empty());
    EXPECT_TRUE(m.normals.empty());
}

TEST(ShapeMeshTest, ObjMixedFaceFormatsAndTexcoords) {
    const auto m = buildShapeMesh(objShape("mixed.obj",
                                           "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                           "vt 0 0\nvt 0.5 0\nvt 0.5 0.5\nvt 0 0.5\n"
                                           "vn 0 0 1\n"
                                           "f 1 2 3\n"            // v
                                           "f 1/1 3/3 4/4\n"      // v/vt
                                           "f 1//1 2//1 3//1\n"   // v//vn
                                           "f 1/1/1 2/2/1 3/3/1 4/4/1\n"));  // v/vt/vn quad
    ASSERT_EQ(m.triangles.size(), 5u);
    EXPECT_NEAR(areaTowards(m, Vec3(0, 0, 1)), 2.5, 1e-6);
    ASSERT_EQ(m.texcoords.size(), m.positions.size());
    for (size_t v = 0; v < m.positions.size(); ++v) {
        const bool fromVt = v >= 3 && !(v >= 6 && v < 9);  // the plain and v//vn faces have none
        const Vec2 expected = fromVt ? Vec2(m.positions[v].x / 2, m.positions[v].y / 2) : Vec2(0.0f);
        EXPECT_EQ(m.texcoords[v], expected) << "corner " << v;
    }
    // Faces without vn leave zero normals, so the whole mesh is shaded flat.
    EXPECT_TRUE(m.normals.empty());
    // Only v//vn and v/vt/vn faces: smooth normals are kept.
    const auto smooth = buildShapeMesh(objShape("normals.obj",
                                                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                                                "f 1//1 2//1 3//1\nf 1/1/1 3/1/1 4/1/1\n"));
    ASSERT_EQ(smooth.normals.size(), smooth.positions.size());
    EXPECT_EQ(smooth.normals[4], Vec3(0, 0, 1));
}

TEST(ShapeMeshTest, ObjBadIndicesAreSceneErrors) {
    auto s = objShape("bad-vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/5 3/1\n");
    s.where = {"room.xml", 12, "<shape type=\"obj\">"};
    expectSceneErrorNaming(s, "bad-vt.obj");
    s.filename = scratchFile("bad-quad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 9\n");
    expectSceneErrorNaming(s, "bad-quad.obj");
}

// --- .serialized shapes ---

void putBytes(std::string& out, const void* data, size_t size) { out.append(static_cast<const char*>(data), size); }

// A version-4 .serialized file (little-endian host) holding each mesh in `meshes`: float
// positions, normals when given, texcoords when given, uint32 triangles.
std::filesystem::path serializedFile(const std::string& name, const std::vector<TriangleMesh>& meshes) {
    std::string file;
    std::vector<uint64_t> offsets;
    for (const TriangleMesh& m : meshes) {
        std::string raw;
        const uint32_t flags = 0x1000 | (m.normals.empty() ? 0 : 0x1) | (m.texcoords.empty() ? 0 : 0x2);
        const uint64_t counts[2] = {m.positions.size(), m.triangles.size()};
        putBytes(raw, &flags, 4);
        raw.append("mesh", 5);
        putBytes(raw, counts, 16);
        putBytes(raw, m.positions.data(), 12 * m.positions.size());
        putBytes(raw, m.normals.data(), 12 * m.normals.size());
        putBytes(raw, m.texcoords.data(), 8 * m.texcoords.size());
        putBytes(raw, m.triangles.data(), 12 * m.triangles.size());
        uLongf size = compressBound(uLong(raw.size()));
        std::string z(size, '\0');
        EXPECT_EQ(compress(reinterpret_cast<Bytef*>(z.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
                           uLong(raw.size())),
                  Z_OK);
        offsets.push_back(file.size());
        const uint16_t header[2] = {0x041C, 4};
        putBytes(file, header, 4);
        file.append(z.data(), size);
    }
    putBytes(file, offsets.data(), 8 * offsets.size());
    const uint32_t count = uint32_t(meshes.size());
    putBytes(file, &count, 4);
    return scratchFile(name, file);
}

TEST(ShapeMeshTest, SerializedShapesAreTransformedToWorld) {
    TriangleMesh quad;
    quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    quad.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    quad.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    quad.triangles = {{0, 1, 2}, {0, 2, 3}};
    TriangleMesh triangle;
    triangle.positions = {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    triangle.triangles = {{0, 1, 2}};
    auto s = shape(Kind::Serialized);
    s.filename = serializedFile("two.serialized", {triangle, quad});
    s.shapeIndex = 1;
    // z' = x + 2z tilts the quad's plane; normals follow the inverse transpose.
    s.toWorld = Transform::fromRowMajor({1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 2, 0, 0, 0, 0, 1})
                    .then(Transform::translate(Vec3(5, 0, 0)));
    const auto m = buildShapeMesh(s);
    ASSERT_EQ(m.triangles.size(), 2u);
    EXPECT_EQ(m.positions[2], Vec3(6, 1, 1));
    ASSERT_EQ(m.texcoords.size(), quad.texcoords.size());
    for (size_t v = 0; v < quad.texcoords.size(); ++v)  // Mitsuba's v = 0 is the top row: stored as 1 - v
        EXPECT_EQ(m.texcoords[v], Vec2(quad.texcoords[v].x, 1 - quad.texcoords[v].y));
    ASSERT_EQ(m.normals.size(), 4u);
    const Vec3 tilted = Vec3(-1, 0, 1).normalized();
    EXPECT_LT((m.normals[0] - tilted).length(), 1e-6f);
    EXPECT_LT((m.geometricNormal(0) - tilted).length(), 1e-6f);
    // faceNormals drops the file's normals; shape 0 has none to begin with.
    s.faceNormals = true;
    EXPECT_TRUE(buildShapeMesh(s).normals.empty());
    s.shapeIndex = 0;
    s.faceNormals = false;
    const auto first = buildShapeMesh(s);
    EXPECT_EQ(first.triangles.size(), 1u);
    EXPECT_TRUE(first.normals.empty());
    EXPECT_TRUE(first.texcoords.empty());
    EXPECT_NEAR(totalArea(first), 1.0, 1e-6);  // x = 0 on it, so only z *= 2 acts
}

TEST(ShapeMeshTest, SerializedErrorsAreSceneErrors) {
    TriangleMesh triangle;
    triangle.positions = {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    triangle.triangles = {{0, 1, 2}};
    auto s = shape(Kind::Serialized);
    s.where = {"room.xml", 12, "<shape type=\"serialized\">"};
    s.filename = serializedFile("one.serialized", {triangle});
    s.shapeIndex = 3;
    expectSceneErrorNaming(s, "holds 1 shape");
    s.filename = std::filesystem::path(testing::TempDir()) / "no-such-mesh.serialized";
    s.shapeIndex = 0;
    expectSceneErrorNaming(s, "no-such-mesh.serialized");
    s.filename = scratchFile("not-serialized.serialized", "this is not a mesh at all");
    expectSceneErrorNaming(s, "format id");
}

// Found by fuzzing: 3 * index overflowed int, so a huge index passed the bounds
// check and read outside the vertex array. Each is refused, naming the mesh.
TEST(ShapeMeshTest, HugeObjIndicesAreSceneErrors) {
    auto s = shape(Kind::Obj);
    s.where = {"room.xml", 12, "<shape type=\"obj\">"};
    const std::string vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\n";
    s.filename = scratchFile("huge-vertex.obj", vertices + "f 1 2 1431655766\n");
    expectSceneErrorNaming(s, "huge-vertex.obj");
    s.filename = scratchFile("huge-normal.obj", vertices + "f 1//1 2//1 3//715827883\n");
    expectSceneErrorNaming(s, "huge-normal.obj");
    s.filename = scratchFile("huge-texcoord.obj", vertices + "f 1/1 2/1 3/1073741825\n");
    expectSceneErrorNaming(s, "huge-texcoord.obj");
}

}  // namespace
}  // namespace vrl

