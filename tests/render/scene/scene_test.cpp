// Tests of Scene: ray queries against Embree, transmittance through null
// boundaries, medium tracking across shapes, the boundary-convexity flag the
// VRL estimators rely on, Mitsuba's default-BSDF rule and build-time errors.
#include "render/scene/scene.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace vrl {
namespace {

using Kind = ShapeDescription::Kind;

const std::filesystem::path kTestData(VRL_TEST_DATA_DIR);

ShapeDescription shape(Kind kind, const Transform& toWorld = {}) {
    ShapeDescription s;
    s.kind = kind;
    s.toWorld = toWorld;
    return s;
}

ShapeDescription nullShape(Kind kind, int interior, int exterior, const Transform& toWorld = {}) {
    ShapeDescription s = shape(kind, toWorld);
    s.bsdf = test::nullBsdf();
    s.interiorMedium = interior;
    s.exteriorMedium = exterior;
    return s;
}

MediumDescription medium(const std::string& id, const Rgb& sigmaS, const Rgb& sigmaA) {
    MediumDescription m;
    m.id = id;
    m.sigmaS = sigmaS;
    m.sigmaA = sigmaA;
    return m;
}

// No shapes or media; a point light far away only keeps Scene::build from warning.
SceneDescription emptyScene() { return test::cameraAndFarLight(4, 4, 45.0f); }

void expectRgbNear(const Rgb& actual, const Rgb& expected, float relative) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(actual[c], expected[c], relative * expected[c]) << "channel " << c;
}

TEST(SceneTest, IntersectFindsTheCubeFaces) {
    auto d = emptyScene();
    d.shapes.push_back(shape(Kind::Cube, Transform::translate(Vec3(0, 0, 5))));  // z in [4, 6]
    const auto scene = Scene::build(d);
    Ray ray{Vec3(0.2f, 0.3f, 0.0f), Vec3(0, 0, 1)};
    const auto front = scene->intersect(ray);
    ASSERT_TRUE(front);
    EXPECT_NEAR(front->t, 4.0f, 1e-5f);
    EXPECT_LT((front->position - Vec3(0.2f, 0.3f, 4.0f)).length(), 1e-5f);
    EXPECT_LT((front->geometricNormal - Vec3(0, 0, -1)).length(), 1e-6f);
    EXPECT_LT((front->shadingNormal - Vec3(0, 0, -1)).length(), 1e-6f);
    EXPECT_EQ(front->shape, 0u);
    EXPECT_TRUE(scene->occluded(ray));

    ray.tMax = 3.9f;  // stops short of the front face
    EXPECT_FALSE(scene->intersect(ray));
    EXPECT_FALSE(scene->occluded(ray));

    ray.tMax = kInfinity;
    ray.tMin = 4.5f;  // starts past the front face: the back face at z = 6
    const auto back = scene->intersect(ray);
    ASSERT_TRUE(back);
    EXPECT_NEAR(back->t, 6.0f, 1e-5f);
    EXPECT_LT((back->geometricNormal - Vec3(0, 0, 1)).length(), 1e-6f);
    EXPECT_TRUE(scene->occluded(ray));
    ray.tMax = 5.9f;
    EXPECT_FALSE(scene->occluded(ray));

    EXPECT_FALSE(scene->intersect(Ray{Vec3(3, 0, 0), Vec3(0, 0, 1)}));  // passes beside it
}

// The rectangle's uv map is u = (x + 1) / 2, v = (1 - y) / 2 in its own frame
// (shape_mesh.h: Mitsuba's v, flipped to Texture's bottom-row convention), linear over its whole plane: texcoordOnPlane must give it for points
// of the plane inside the hit triangle, in the other triangle, beyond the rectangle,
// and for points off the plane (their projection).
TEST(SceneTest, TexcoordOnPlaneExtendsTheHitTrianglesUvMap) {
    auto d = emptyScene();
    const Transform toWorld =
        Transform::scale(Vec3(2.0f, 3.0f, 1.0f)).then(Transform::rotate(Vec3(1, 0, 0), 50.0f)).then(
            Transform::translate(Vec3(0.5f, -0.25f, 6.0f)));
    d.shapes.push_back(shape(Kind::Rectangle, toWorld));
    const auto scene = Scene::build(d);
    const auto hit = scene->intersect(Ray{Vec3(0, 0, 0), Vec3(0.05f, -0.02f, 1.0f).normalized()});
    ASSERT_TRUE(hit);
    const Vec3 normal = toWorld.applyNormal(Vec3(0, 0, 1)).normalized();
    for (const Vec2& local : {Vec2(0.3f, -0.6f), Vec2(-0.7f, 0.8f), Vec2(0.9f, 0.9f), Vec2(2.5f, -1.7f),
                             Vec2(-3.0f, 0.1f)}) {
        for (const float offset : {0.0f, 0.4f, -1.3f}) {
            const Vec3 point = toWorld.applyPoint(Vec3(local.x, local.y, 0.0f)) + normal * offset;
            const Vec2 uv = scene->texcoordOnPlane(*hit, point);
            EXPECT_NEAR(uv.x, 0.5f * (local.x + 1.0f), 2e-5f) << local << " offset " << offset;
            EXPECT_NEAR(uv.y, 0.5f * (1.0f - local.y), 2e-5f) << local << " offset " << offset;
        }
    }
    // At the hit itself: the hit's own uv.
    const Vec2 own = scene->texcoordOnPlane(*hit, hit->position);
    EXPECT_NEAR(own.x, hit->uv.x, 1e-5f);
    EXPECT_NEAR(own.y, hit->uv.y, 1e-5f);
}

// A cube [-1, 1]^3 with a null boundary around an absorbing, scattering medium.
SceneDescription mediumCube(const Rgb& sigmaS, const Rgb& sigmaA) {
    auto d = emptyScene();
    d.media.push_back(medium("ink", sigmaS, sigmaA));
    d.shapes.push_back(nullShape(Kind::Cube, 0, -1));
    return d;
}

TEST(SceneTest, TransmittanceThroughANullCubeIsBeerLambertOverTheChord) {
    const Rgb sigmaT = Rgb(0.1f, 0.2f, 0.3f) + Rgb(0.4f, 0.8f, 1.7f);
    const auto scene = Scene::build(mediumCube(Rgb(0.1f, 0.2f, 0.3f), Rgb(0.4f, 0.8f, 1.7f)));
    ASSERT_TRUE(scene->hasNullSurfaces());
    // Straight through: chord 2.
    expectRgbNear(scene->transmittance(Vec3(-3, 0.2f, 0.1f), Vec3(3, 0.2f, 0.1f), -1), exp(-sigmaT * 2.0f), 1e-5f);
    // Obliquely along (0.8, 0.6, 0): enters at x = -1, leaves at x = 1, chord 2 / 0.8 = 2.5.
    expectRgbNear(scene->transmittance(Vec3(-2, -1.5f, 0.3f), Vec3(2, 1.5f, 0.3f), -1), exp(-sigmaT * 2.5f), 1e-5f);
    // Either direction.
    expectRgbNear(scene->transmittance(Vec3(2, 1.5f, 0.3f), Vec3(-2, -1.5f, 0.3f), -1), exp(-sigmaT * 2.5f), 1e-5f);
    // From inside to outside: chord 1.
    expectRgbNear(scene->transmittance(Vec3(0, 0, 0), Vec3(0, 3, 0), 0), exp(-sigmaT * 1.0f), 1e-5f);
    // Inside to inside: no boundary crossed.
    expectRgbNear(scene->transmittance(Vec3(-0.5f, 0, 0), Vec3(0.5f, 0.5f, 0), 0), exp(-sigmaT * std::sqrt(1.25f)),
                  1e-5f);
    // Outside to outside beside the cube: vacuum.
    EXPECT_EQ(scene->transmittance(Vec3(-3, 2, 0), Vec3(3, 2, 0), -1), Rgb(1.0f));
}

TEST(SceneTest, TransmittanceIsZeroThroughOpaqueShapesAndOneInVacuum) {
    auto d = emptyScene();
    d.shapes.push_back(shape(Kind::Cube));  // diffuse by default
    const auto opaque = Scene::build(d);
    ASSERT_FALSE(opaque->hasNullSurfaces());
    EXPECT_EQ(opaque->transmittance(Vec3(-3, 0, 0), Vec3(3, 0, 0), -1), Rgb(0.0f));
    EXPECT_EQ(opaque->transmittance(Vec3(-3, 2, 0), Vec3(3, 2, 0), -1), Rgb(1.0f));
    EXPECT_EQ(Scene::build(emptyScene())->transmittance(Vec3(0, 0, 0), Vec3(100, 5, -7), -1), Rgb(1.0f));

    // An opaque wall behind a null cube: the walk through the boundary stops at the wall.
    auto mixed = mediumCube(Rgb(0.0f), Rgb(0.5f));
    mixed.shapes.push_back(shape(Kind::Rectangle, Transform::rotate(Vec3(0, 1, 0), 90.0f).then(
                                                      Transform::translate(Vec3(2, 0, 0)))));
    const auto scene = Scene::build(mixed);
    EXPECT_EQ(scene->transmittance(Vec3(-3, 0, 0), Vec3(3, 0, 0), -1), Rgb(0.0f));
    expectRgbNear(scene->transmittance(Vec3(-3, 0, 0), Vec3(1.5f, 0, 0), -1), exp(Rgb(-0.5f * 2.0f)), 1e-5f);
}

TEST(SceneTest, MediumAfterFollowsTheOutwardNormal) {
    auto d = emptyScene();
    d.media = {medium("inner", Rgb(1.0f), Rgb(0.0f)), medium("outer", Rgb(0.5f), Rgb(0.0f))};
    d.shapes.push_back(nullShape(Kind::Cube, 0, 1));
    d.shapes.push_back(nullShape(Kind::Cube, -1, -1, Transform::translate(Vec3(0, 5, 0))));  // declares no media
    const auto scene = Scene::build(d);
    const Vec3 plusX(1, 0, 0);
    const auto entering = scene->intersect(Ray{Vec3(-3, 0, 0), plusX});
    ASSERT_TRUE(entering);
    ASSERT_LT(entering->geometricNormal.dot(plusX), 0.0f);
    EXPECT_EQ(scene->mediumAfter(*entering, plusX, 1), 0);
    EXPECT_EQ(scene->mediumAfter(*entering, -plusX, 0), 1);  // turning back out
    const auto leaving = scene->intersect(Ray{Vec3(0, 0, 0), plusX});
    ASSERT_TRUE(leaving);
    EXPECT_EQ(scene->mediumAfter(*leaving, plusX, 0), 1);

    const auto plain = scene->intersect(Ray{Vec3(-3, 5, 0), plusX});
    ASSERT_TRUE(plain);
    ASSERT_EQ(plain->shape, 1u);
    EXPECT_FALSE(scene->shapes()[1].changesMedium);
    for (const int current : {-1, 0, 1}) {
        EXPECT_EQ(scene->mediumAfter(*plain, plusX, current), current);
        EXPECT_EQ(scene->mediumAfter(*plain, -plusX, current), current);
    }
}

std::filesystem::path scratchObj(const std::string& name, const std::string& contents) {
    const auto dir = std::filesystem::path(testing::TempDir()) / "scene_test";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / name) << contents;
    return dir / name;
}

bool convexityOfMediumInside(ShapeDescription boundary) {
    auto d = emptyScene();
    d.media.push_back(medium("fog", Rgb(1.0f), Rgb(0.1f)));
    boundary.bsdf = test::nullBsdf();
    boundary.interiorMedium = 0;
    d.shapes.push_back(boundary);
    return Scene::build(d)->media()[0].boundaryConvex();
}

TEST(SceneTest, MediaInsideConvexNullShapesAreConvex) {
    EXPECT_TRUE(convexityOfMediumInside(shape(Kind::Cube, Transform::rotate(Vec3(1, 1, 0), 30.0f))));
    auto sphere = shape(Kind::Sphere);
    sphere.center = Vec3(1, 2, 3);
    sphere.radius = 2.5f;
    EXPECT_TRUE(convexityOfMediumInside(sphere));
    auto ico = shape(Kind::Obj, Transform::scale(Vec3(3.0f)));
    ico.filename = kTestData / "../scenes/meshes/icosahedron.obj";
    EXPECT_TRUE(convexityOfMediumInside(ico));
}

TEST(SceneTest, MediaInsideNonConvexNullShapesAreNotConvex) {
    // An octahedron whose top apex is pushed down to z = -0.5, below the equator:
    // closed, outward-facing, with a conical dent.
    auto dented = shape(Kind::Obj);
    dented.filename = scratchObj("dented-octahedron.obj",
                                 "v 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nv 0 0 -0.5\nv 0 0 -1\n"
                                 "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n"
                                 "f 2 1 6\nf 3 2 6\nf 4 3 6\nf 1 4 6\n");
    EXPECT_FALSE(convexityOfMediumInside(dented));
    // The same file with the apex at z = +1 is convex (control for the winding above).
    auto octahedron = dented;
    octahedron.filename = scratchObj("octahedron.obj",
                                     "v 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
                                     "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n"
                                     "f 2 1 6\nf 3 2 6\nf 4 3 6\nf 1 4 6\n");
    EXPECT_TRUE(convexityOfMediumInside(octahedron));
    // One medium inside two disjoint cubes: a segment between them leaves it.
    auto d = emptyScene();
    d.media.push_back(medium("fog", Rgb(1.0f), Rgb(0.1f)));
    d.shapes.push_back(nullShape(Kind::Cube, 0, -1, Transform::translate(Vec3(-3, 0, 0))));
    d.shapes.push_back(nullShape(Kind::Cube, 0, -1, Transform::translate(Vec3(3, 0, 0))));
    EXPECT_FALSE(Scene::build(d)->media()[0].boundaryConvex());
}

TEST(SceneTest, SceneFillingMediumConvexity) {
    // Only opaque objects inside: convex (segments through walls are blocked anyway).
    EXPECT_TRUE(Scene::build(test::smallSmokeRoom())->media()[0].boundaryConvex());
    // Surrounding a null sphere of another medium: a segment can pass through it.
    auto d = test::smallSmokeRoom();
    d.media.push_back(medium("cloud", Rgb(2.0f), Rgb(0.0f)));
    auto cloud = nullShape(Kind::Sphere, 1, 0);
    cloud.radius = 0.5f;
    d.shapes.push_back(cloud);
    const auto scene = Scene::build(d);
    EXPECT_FALSE(scene->media()[0].boundaryConvex());
    EXPECT_TRUE(scene->media()[1].boundaryConvex());
}

TEST(SceneTest, BuildsTheSmokeRoomScene) {
    const auto scene = Scene::build(parseMitsubaScene(kTestData / "../scenes/smoke-room.xml"));
    EXPECT_EQ(scene->shapes().size(), 4u);
    ASSERT_EQ(scene->media().size(), 1u);
    EXPECT_EQ(scene->emitters().size(), 1u);
    EXPECT_EQ(scene->cameraMedium(), 0);
    EXPECT_EQ(scene->emitters()[0]->medium, 0);  // the spot light sits in the camera's smoke
    EXPECT_TRUE(scene->media()[0].boundaryConvex());
    EXPECT_FALSE(scene->hasNullSurfaces());
    EXPECT_EQ(scene->shapes()[3].mesh.triangles.size(), 20u);  // the icosahedron
    EXPECT_EQ(scene->camera().width(), 320);
}

void expectBuildErrorNaming(const SceneDescription& d, const std::string& what) {
    try {
        Scene::build(d);
        FAIL() << "expected a SceneError naming " << what;
    } catch (const SceneError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(what), std::string::npos) << message;
        EXPECT_NE(message.find("hand.xml:7"), std::string::npos) << message;
    }
}

TEST(SceneTest, InvalidMediaAreSceneErrors) {
    auto d = emptyScene();
    d.media.push_back(medium("ink", Rgb(0.5f), Rgb(0.1f, -0.2f, 0.1f)));
    d.media.back().where = {"hand.xml", 7, "<medium type=\"homogeneous\">"};
    expectBuildErrorNaming(d, "ink");
    expectBuildErrorNaming(d, "sigmaA");
    // A shape referring to a medium that does not exist.
    d = emptyScene();
    d.shapes.push_back(nullShape(Kind::Cube, 2, -1));
    d.shapes.back().where = {"hand.xml", 7, "<shape type=\"cube\">"};
    expectBuildErrorNaming(d, "medium index 2");
}

TEST(SceneTest, DefaultBsdfFollowsMitsuba) {
    auto d = emptyScene();
    d.media.push_back(medium("fog", Rgb(1.0f), Rgb(0.0f)));
    ShapeDescription between = shape(Kind::Cube);
    between.interiorMedium = 0;
    d.shapes.push_back(between);  // 0: between media, no bsdf -> null
    ShapeDescription outsideOnly = shape(Kind::Sphere);
    outsideOnly.exteriorMedium = 0;
    d.shapes.push_back(outsideOnly);  // 1: exterior only -> null
    d.shapes.push_back(shape(Kind::Disk));  // 2: no media -> diffuse 0.5
    ShapeDescription lamp = shape(Kind::Rectangle);
    lamp.exteriorMedium = 0;
    lamp.areaRadiance = Rgb(3.0f);
    d.shapes.push_back(lamp);  // 3: area emitter between media -> diffuse
    ShapeDescription blue = shape(Kind::Cube);
    blue.interiorMedium = 0;
    blue.bsdf = test::diffuseBsdf(Rgb(0.1f, 0.2f, 0.9f), true);
    d.shapes.push_back(blue);  // 4: an explicit bsdf wins
    const auto scene = Scene::build(d);
    const auto& s = scene->shapes();
    EXPECT_TRUE(s[0].bsdf.isNull());
    EXPECT_TRUE(s[1].bsdf.isNull());
    EXPECT_EQ(s[2].bsdf.kind(), BsdfDescription::Kind::Diffuse);
    EXPECT_EQ(s[2].bsdf.albedo(Vec2(0.5f)), Rgb(0.5f));
    EXPECT_FALSE(s[2].bsdf.twoSided());
    EXPECT_EQ(s[3].bsdf.kind(), BsdfDescription::Kind::Diffuse);
    EXPECT_EQ(s[3].emitter, 0);  // area emitters come before the point light
    EXPECT_EQ(s[4].bsdf.kind(), BsdfDescription::Kind::Diffuse);
    EXPECT_EQ(s[4].bsdf.albedo(Vec2(0.5f)), Rgb(0.1f, 0.2f, 0.9f));
    EXPECT_TRUE(s[4].bsdf.twoSided());
    EXPECT_TRUE(scene->hasNullSurfaces());
}


// A medium's null boundary flush with (or a hair inside) an opaque room: shadow
// rays crossing the boundary must still stop at the wall, whatever the shape order.
TEST(SceneTest, OpaqueWallFlushWithNullBoundaryStillBlocks) {
    for (int order = 0; order < 2; ++order) {
        for (float wall : {1.0f, 1.00001f, 1.0001f, 1.001f}) {
            SceneDescription d;
            d.sensor = test::cameraAtOrigin(4, 4, 45.0f);
            MediumDescription m;
            m.id = "fog";
            m.sigmaS = Rgb(0.0f);
            m.sigmaA = Rgb(0.5f);
            d.media.push_back(m);
            ShapeDescription box;
            box.kind = ShapeDescription::Kind::Cube;
            box.bsdf = test::nullBsdf();
            box.interiorMedium = 0;
            ShapeDescription room;
            room.kind = ShapeDescription::Kind::Cube;
            room.flipNormals = true;
            room.toWorld = Transform::scale(Vec3(wall));
            if (order == 0) {
                d.shapes = {box, room};
            } else {
                d.shapes = {room, box};
            }
            const auto scene = Scene::build(d);
            for (int i = 0; i < 200; ++i) {
                const float a = 0.031f * i;
                const Vec3 from(0.1f * std::sin(a), 0.2f * std::cos(a), 0.05f);
                const Vec3 to(3.0f, 0.5f * std::sin(3 * a), 0.7f * std::cos(2 * a));
                ASSERT_EQ(scene->transmittance(from, to, 0), Rgb(0.0f)) << "order " << order << " wall " << wall << " ray " << i;
            }
        }
    }
}

// VRL shading skips occlusion rays only where nothing can block a segment.
TEST(SceneTest, MediumNeedsVisibilityOnlyWhenSomethingCanOcclude) {
    EXPECT_FALSE(Scene::build(test::mediumOnlyCube(Rgb(0.5f), Rgb(0.1f), 0.0f))->mediumNeedsVisibility(0));
    EXPECT_FALSE(Scene::build(test::pointLightInInfiniteMedium(Rgb(1.0f), Vec3(0.0f), Rgb(0.5f), Rgb(0.1f), 0.0f))
                     ->mediumNeedsVisibility(0));
    EXPECT_TRUE(Scene::build(test::litRoomWithOccluder(Rgb(0.5f), Rgb(0.1f), 0.0f))->mediumNeedsVisibility(0));
    // A convex medium box with an opaque object inside it needs visibility too.
    SceneDescription d = test::mediumOnlyCube(Rgb(0.5f), Rgb(0.1f), 0.0f);
    ShapeDescription inside;
    inside.kind = ShapeDescription::Kind::Cube;
    inside.toWorld = Transform::scale(Vec3(0.2f));
    inside.exteriorMedium = 0;
    inside.bsdf = BsdfDescription{};
    d.shapes.push_back(inside);
    EXPECT_TRUE(Scene::build(d)->mediumNeedsVisibility(0));
}

}  // namespace
}  // namespace vrl
