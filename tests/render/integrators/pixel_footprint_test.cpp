// footprintTexcoords: each of the grid's points must carry the texture coordinates
// the camera ray through it finds on the surface (Scene::intersect's uv), on a
// tilted, scaled rectangle seen in perspective: whole pixels, a pixel that straddles
// the rectangle's diagonal (two triangles, one linear uv map) and a stratum of a
// pixel (K x K shading points). A plane seen edge-on gives none.
#include "render/integrators/pixel_footprint.h"

#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

namespace vrl {
namespace {

SceneDescription tiltedRectangle(const Transform& toWorld) {
    SceneDescription d = test::cameraAndFarLight(32, 24, 40.0f);
    ShapeDescription rectangle;
    rectangle.kind = ShapeDescription::Kind::Rectangle;
    rectangle.toWorld = toWorld;
    d.shapes.push_back(rectangle);
    return d;
}

// Every grid point's uv against the uv of the hit its own ray finds.
void expectGridMatchesHits(const Scene& scene, const FilmSquare& square, const char* what) {
    SCOPED_TRACE(what);
    const Ray centre = scene.camera().generateRay(square.x + 0.5f * square.size, square.y + 0.5f * square.size);
    const auto hit = scene.intersect(centre);
    ASSERT_TRUE(hit);
    const auto uvs = footprintTexcoords(scene, square, *hit);
    ASSERT_TRUE(uvs);
    const float step = square.size / float(kFootprintSide);
    Vec2 low(1e30f), high(-1e30f);
    for (int j = 0; j < kFootprintSide; ++j) {
        for (int i = 0; i < kFootprintSide; ++i) {
            const Ray ray = scene.camera().generateRay(square.x + (float(i) + 0.5f) * step,
                                                       square.y + (float(j) + 0.5f) * step);
            const auto own = scene.intersect(ray);
            ASSERT_TRUE(own);
            const Vec2 uv = (*uvs)[size_t(j * kFootprintSide + i)];
            EXPECT_NEAR(uv.x, own->uv.x, 2e-5f) << "point " << i << ", " << j;
            EXPECT_NEAR(uv.y, own->uv.y, 2e-5f) << "point " << i << ", " << j;
            low.x = std::min(low.x, uv.x), low.y = std::min(low.y, uv.y);
            high.x = std::max(high.x, uv.x), high.y = std::max(high.y, uv.y);
        }
    }
    // The points spread over the square (not one texel repeated).
    EXPECT_GT((high - low).length(), 1e-4f);
}

TEST(PixelFootprint, GridPointsCarryTheUvsTheirRaysFind) {
    const Transform toWorld =
        Transform::scale(Vec3(3.0f, 2.0f, 1.0f)).then(Transform::rotate(Vec3(1, 0, 0), -55.0f)).then(
            Transform::translate(Vec3(0.2f, 0.1f, 5.0f)));
    const auto scene = Scene::build(tiltedRectangle(toWorld));
    expectGridMatchesHits(*scene, FilmSquare{10.0f, 7.0f, 1.0f}, "pixel (10, 7)");
    expectGridMatchesHits(*scene, FilmSquare{21.0f, 15.0f, 1.0f}, "pixel (21, 15)");
    expectGridMatchesHits(*scene, FilmSquare{13.5f, 11.0f, 0.5f}, "a stratum of pixel (13, 11)");
    // The pixel whose centre ray passes nearest the diagonal: its points fall in both triangles.
    int straddling = 0;
    for (int y = 0; y < 24 && straddling == 0; ++y) {
        for (int x = 0; x < 32; ++x) {
            const auto a = scene->intersect(scene->camera().generateRay(float(x) + 0.01f, float(y) + 0.01f));
            const auto b = scene->intersect(scene->camera().generateRay(float(x) + 0.99f, float(y) + 0.99f));
            if (a && b && a->triangle != b->triangle) {
                expectGridMatchesHits(*scene, FilmSquare{float(x), float(y), 1.0f}, "a pixel on the diagonal");
                ++straddling;
                break;
            }
        }
    }
    EXPECT_EQ(straddling, 1) << "no pixel straddles the two triangles: the test's geometry changed";
}

TEST(PixelFootprint, NoneForAPlaneSeenEdgeOn) {
    const auto scene = Scene::build(tiltedRectangle(Transform::translate(Vec3(0.0f, 0.0f, 5.0f))));
    auto hit = scene->intersect(scene->camera().generateRay(16.0f, 12.0f));
    ASSERT_TRUE(hit);
    EXPECT_TRUE(footprintTexcoords(*scene, FilmSquare{15.5f, 11.5f, 1.0f}, *hit));
    // The same point with its plane turned to contain the camera's rays: none meets it.
    hit->geometricNormal = Vec3(1.0f, 0.0f, 0.0f);
    hit->position = Vec3(0.0f, 0.0f, 5.0f);
    EXPECT_FALSE(footprintTexcoords(*scene, FilmSquare{15.5f, 11.5f, 1.0f}, *hit)) << "the plane x = 0 passes through the camera";
}

}  // namespace
}  // namespace vrl
