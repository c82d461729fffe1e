// Tests of PerspectiveCamera against Mitsuba's perspective sensor: the image
// orientation (+x camera space is the image's left, +y its top), the field of
// view along each fovAxis, and the near/far clip planes.
#include "render/scene/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>
#include <utility>

namespace vrl {
namespace {

using FovAxis = SensorDescription::FovAxis;

// A camera at (1, 2, 3) looking along (0.6, 0.8, 0) with +z up: a frame with no
// axis aligned to the world's, so a swapped or negated axis shows.
SensorDescription tiltedSensor(int width, int height, float fov, FovAxis axis) {
    SensorDescription sensor;
    sensor.toWorld = Transform::lookAt(Vec3(1, 2, 3), Vec3(4, 6, 3), Vec3(0, 0, 1));
    sensor.width = width;
    sensor.height = height;
    sensor.fov = fov;
    sensor.fovAxis = axis;
    return sensor;
}

Vec3 cameraSpace(const SensorDescription& sensor, const Vec3& worldDirection) {
    return sensor.toWorld.inverse().applyVector(worldDirection);
}

// Angle (radians) between a ray and the camera's viewing axis, in double.
double angleToAxis(const SensorDescription& sensor, const Ray& ray) {
    const Vec3 local = cameraSpace(sensor, ray.direction);
    return std::atan2(std::hypot(double(local.x), double(local.y)), double(local.z));
}

double radians(double degrees) { return degrees * M_PI / 180.0; }

TEST(CameraTest, CentreOfAnOddFilmLooksAlongPlusZ) {
    const auto sensor = tiltedSensor(5, 3, 50.0f, FovAxis::X);
    const PerspectiveCamera camera(sensor);
    EXPECT_EQ(camera.width(), 5);
    EXPECT_EQ(camera.height(), 3);
    EXPECT_LT((camera.position() - Vec3(1, 2, 3)).length(), 1e-6f);
    const Ray ray = camera.generateRay(2.5f, 1.5f);  // the centre of pixel (2, 1)
    EXPECT_LT((ray.direction - Vec3(0.6f, 0.8f, 0.0f)).length(), 1e-6f);
    EXPECT_LT((sensor.toWorld.applyVector(Vec3(0, 0, 1)) - Vec3(0.6f, 0.8f, 0.0f)).length(), 1e-6f);
}

TEST(CameraTest, ImageLeftIsPlusXAndImageTopIsPlusY) {
    const auto sensor = tiltedSensor(5, 3, 50.0f, FovAxis::X);
    const PerspectiveCamera camera(sensor);
    const double tanHalfX = std::tan(radians(25.0)), tanHalfY = tanHalfX * 3.0 / 5.0;
    // Pixel (0, 1): ndc x = 2 * 0.5 / 5 - 1 = -0.8, so the camera-space direction is
    // proportional to (+0.8 tanHalfX, 0, 1).
    const Vec3 left = cameraSpace(sensor, camera.generateRay(0.5f, 1.5f).direction);
    EXPECT_GT(left.x, 0.0f);
    EXPECT_NEAR(left.x / left.z, 0.8 * tanHalfX, 1e-5);
    EXPECT_NEAR(left.y, 0.0f, 1e-6f);
    // Pixel (4, 1) is on the right: negative x.
    EXPECT_NEAR(cameraSpace(sensor, camera.generateRay(4.5f, 1.5f).direction).x / left.z, -0.8 * tanHalfX, 1e-5);
    // Pixel (2, 0): ndc y = 2 * 0.5 / 3 - 1 = -2/3, direction ~ (0, +2/3 tanHalfY, 1).
    const Vec3 top = cameraSpace(sensor, camera.generateRay(2.5f, 0.5f).direction);
    EXPECT_GT(top.y, 0.0f);
    EXPECT_NEAR(top.y / top.z, 2.0 / 3.0 * tanHalfY, 1e-5);
    EXPECT_NEAR(top.x, 0.0f, 1e-6f);
    // In world terms (lookat: +x = up x dir): image left is (-0.8, 0.6, 0), top is +z.
    EXPECT_GT(camera.generateRay(0.5f, 1.5f).direction.dot(Vec3(-0.8f, 0.6f, 0.0f)), 0.1f);
    EXPECT_GT(camera.generateRay(2.5f, 0.5f).direction.z, 0.1f);
}

struct FovCase {
    FovAxis axis;
    int width, height;
    float filmX, filmY;  // a film position on the edge (or corner) along the fov's axis
};

TEST(CameraTest, FieldOfViewSpansTheChosenAxis) {
    const float fov = 64.0f;
    const FovCase cases[] = {
        {FovAxis::X, 40, 30, 0.0f, 15.0f},         {FovAxis::X, 30, 40, 30.0f, 20.0f},
        {FovAxis::Y, 40, 30, 20.0f, 0.0f},         {FovAxis::Y, 30, 40, 15.0f, 40.0f},
        {FovAxis::Diagonal, 40, 30, 0.0f, 0.0f},   {FovAxis::Diagonal, 30, 40, 30.0f, 40.0f},
        {FovAxis::Smaller, 40, 30, 20.0f, 0.0f},   {FovAxis::Smaller, 30, 40, 0.0f, 20.0f},
        {FovAxis::Larger, 40, 30, 0.0f, 15.0f},    {FovAxis::Larger, 30, 40, 15.0f, 0.0f},
    };
    for (const FovCase& c : cases) {
        const auto sensor = tiltedSensor(c.width, c.height, fov, c.axis);
        const PerspectiveCamera camera(sensor);
        EXPECT_NEAR(angleToAxis(sensor, camera.generateRay(c.filmX, c.filmY)), radians(fov / 2), 2e-6)
            << "axis " << int(c.axis) << ", film " << c.width << "x" << c.height;
    }
}

TEST(CameraTest, OtherAxisFollowsTheAspectRatio) {
    // fov 90 along x on a 40x30 film: tan(half fov y) = 30/40; along y on 30x40: tan(half fov x) = 30/40.
    auto sensor = tiltedSensor(40, 30, 90.0f, FovAxis::X);
    EXPECT_NEAR(angleToAxis(sensor, PerspectiveCamera(sensor).generateRay(20.0f, 0.0f)), std::atan(0.75), 2e-6);
    sensor = tiltedSensor(30, 40, 90.0f, FovAxis::Y);
    EXPECT_NEAR(angleToAxis(sensor, PerspectiveCamera(sensor).generateRay(0.0f, 20.0f)), std::atan(0.75), 2e-6);
    // Diagonal 90 on 40x30: half diagonal tan = 1, so tan(half x) = 0.8, tan(half y) = 0.6.
    sensor = tiltedSensor(40, 30, 90.0f, FovAxis::Diagonal);
    const PerspectiveCamera camera(sensor);
    EXPECT_NEAR(angleToAxis(sensor, camera.generateRay(0.0f, 15.0f)), std::atan(0.8), 2e-6);
    EXPECT_NEAR(angleToAxis(sensor, camera.generateRay(20.0f, 0.0f)), std::atan(0.6), 2e-6);
}

TEST(CameraTest, RaysSpanTheClipPlanes) {
    auto sensor = tiltedSensor(40, 30, 70.0f, FovAxis::X);
    sensor.nearClip = 0.5f;
    sensor.farClip = 80.0f;
    const PerspectiveCamera camera(sensor);
    const Vec3 axis(0.6f, 0.8f, 0.0f), position(1, 2, 3);
    for (const auto& [x, y] : {std::pair{20.0f, 15.0f}, std::pair{0.0f, 0.0f}, std::pair{33.3f, 2.5f},
                               std::pair{40.0f, 30.0f}}) {
        const Ray ray = camera.generateRay(x, y);
        EXPECT_NEAR(ray.direction.length(), 1.0f, 1e-6f);
        const float cosine = ray.direction.dot(axis);
        ASSERT_GT(cosine, 0.5f);
        // Origin on the near plane, along the ray from the camera's position.
        const Vec3 expectedOrigin = position + ray.direction * (sensor.nearClip / cosine);
        EXPECT_LT((ray.origin - expectedOrigin).length(), 1e-5f) << x << ", " << y;
        EXPECT_NEAR((ray.origin - position).dot(axis), sensor.nearClip, 1e-5f);
        // End on the far plane.
        EXPECT_NEAR(ray.tMax, (sensor.farClip - sensor.nearClip) / cosine, 1e-5f * ray.tMax);
        EXPECT_NEAR((ray.at(ray.tMax) - position).dot(axis), sensor.farClip, 1e-5f * sensor.farClip);
        EXPECT_EQ(ray.tMin, 0.0f);
    }
}

// OpenEXR's camera attributes: a world point on the ray through film position
// (fx, fy) maps to NDC (fx / width, fy / height) with w = its camera depth, and
// worldToCamera puts it on +z with x growing to the image's right.
TEST(CameraTest, WorldToNdcMapsRayPointsToTheirFilmPosition) {
    for (const auto& [width, height, axis] : {std::tuple{64, 48, FovAxis::X}, std::tuple{30, 90, FovAxis::Y},
                                              std::tuple{41, 41, FovAxis::Diagonal}}) {
        const SensorDescription sensor = tiltedSensor(width, height, 53.0f, axis);
        const PerspectiveCamera camera(sensor);
        const Imath::M44f toCamera = camera.worldToCamera(), toNdc = camera.worldToNDC();
        for (const auto& [fx, fy] : {std::pair{0.5f, 0.5f}, std::pair{float(width) - 0.25f, 3.0f},
                                     std::pair{float(width) * 0.5f, float(height) * 0.5f}, std::pair{7.0f, float(height)}}) {
            const Ray ray = camera.generateRay(fx, fy);
            const Vec3 point = ray.origin + ray.direction * 5.0f;
            Imath::V4f p(point.x, point.y, point.z, 1.0f);
            const Imath::V4f ndc = p * toNdc;
            EXPECT_NEAR(ndc.x / ndc.w, fx / float(width), 1e-5f) << width << "x" << height;
            EXPECT_NEAR(ndc.y / ndc.w, fy / float(height), 1e-5f) << width << "x" << height;
            const Imath::V4f c = p * toCamera;
            EXPECT_GT(c.z, 0.0f);
            EXPECT_NEAR(c.w, 1.0f, 1e-6f);
            EXPECT_NEAR(ndc.w, c.z, 1e-4f);
            // x grows to the image's right in OpenEXR's camera space.
            if (fx > float(width) * 0.5f + 1.0f) {
                EXPECT_GT(c.x, 0.0f);
            }
            if (fy < float(height) * 0.5f - 1.0f) {
                EXPECT_GT(c.y, 0.0f);
            }
        }
    }
}

// A crop window: the image is the window's size, pixels and random streams
// keep their film indices, and worldToNDC spans the window (the EXR written).
TEST(CameraTest, CropWindowKeepsFilmPixelsAndItsNdcSpansTheWindow) {
    SensorDescription sensor = tiltedSensor(64, 48, 53.0f, FovAxis::X);
    sensor.crop = FilmCrop{10, 6, 20, 12};
    const PerspectiveCamera camera(sensor), full(tiltedSensor(64, 48, 53.0f, FovAxis::X));
    EXPECT_EQ(camera.width(), 20);
    EXPECT_EQ(camera.height(), 12);
    EXPECT_EQ(camera.filmWidth(), 64);
    EXPECT_EQ(camera.filmHeight(), 48);
    EXPECT_EQ(camera.filmPixelIndex(0, 0), 6u * 64u + 10u);
    EXPECT_EQ(camera.filmPixelIndex(19, 11), full.filmPixelIndex(29, 17));
    const Imath::M44f toNdc = camera.worldToNDC();
    for (const auto& [fx, fy] : {std::pair{10.0f, 6.0f}, std::pair{30.0f, 18.0f}, std::pair{17.5f, 9.25f}}) {
        const Ray ray = camera.generateRay(fx, fy);
        const Vec3 point = ray.origin + ray.direction * 5.0f;
        const Imath::V4f ndc = Imath::V4f(point.x, point.y, point.z, 1.0f) * toNdc;
        EXPECT_NEAR(ndc.x / ndc.w, (fx - 10.0f) / 20.0f, 1e-5f);
        EXPECT_NEAR(ndc.y / ndc.w, (fy - 6.0f) / 12.0f, 1e-5f);
    }
}

// project() inverts generateRay: a point on the ray through film position (fx, fy)
// lands in the pixel holding (fx, fy) (of the crop window) at offset (fx, fy) minus
// that pixel's centre, its camera ray starts where generateRay's does, and points
// off the image, behind the camera or before the near clip plane are not seen; for
// a look-at sensor, the same scaled by 2.5 (clip distances stay world units along
// the ray) and one mirrored by Mitsuba's <scale x="-1"/>.
TEST(CameraTest, ProjectFindsThePixelAndTheRayOfAPoint) {
    const Transform scaled = Transform::scale(Vec3(2.5f)), mirrored = Transform::scale(Vec3(-1.0f, 1.0f, 1.0f));
    for (const Transform* local : {static_cast<const Transform*>(nullptr), &scaled, &mirrored})
        for (const bool cropped : {false, true}) {
            SensorDescription sensor = tiltedSensor(64, 48, 53.0f, FovAxis::X);
            if (local) sensor.toWorld = local->then(sensor.toWorld);
            sensor.nearClip = 0.5f;
            if (cropped) sensor.crop = FilmCrop{10, 6, 20, 12};
            const PerspectiveCamera camera(sensor);
            for (const auto& [fx, fy] : {std::pair{10.5f, 6.25f}, std::pair{29.9f, 17.1f}, std::pair{17.5f, 9.75f}}) {
                const Ray ray = camera.generateRay(fx, fy);
                const Vec3 point = ray.origin + ray.direction * 7.0f;
                const auto seen = camera.project(point);
                ASSERT_TRUE(seen) << fx << ", " << fy;
                EXPECT_EQ(seen->x, int(fx) - camera.cropX0());
                EXPECT_EQ(seen->y, int(fy) - camera.cropY0());
                EXPECT_NEAR(seen->offsetX, fx - std::floor(fx) - 0.5f, 1e-3f);
                EXPECT_NEAR(seen->offsetY, fy - std::floor(fy) - 0.5f, 1e-3f);
                EXPECT_LT((seen->rayOrigin - ray.origin).length(), 1e-4f);
                EXPECT_NEAR(seen->distance, (point - camera.position()).length(), 1e-4f);
                EXPECT_FALSE(camera.project(camera.position() - (point - camera.position())));  // behind
                EXPECT_FALSE(camera.project(camera.position() + ray.direction * 0.3f));  // before the near clip plane
            }
            const Ray off = camera.generateRay(cropped ? 5.0f : -0.5f, 20.0f);  // left of the crop window, or of the film
            EXPECT_FALSE(camera.project(off.origin + off.direction * 3.0f));
        }
}

// The importance is the pinhole's We for a box filter over the pixel: integrated
// over the pixel's solid angle it is exactly 1. Solid angles here come from
// generateRay's directions alone (16 x 16 spherical quads per pixel, each two
// triangles by Van Oosterom and Strackee's formula), not from the film-plane
// geometry project() uses; a corner pixel of a wide camera (fov 100 along x, so
// cos^3 varies across it) and a centre pixel. Tolerance 1e-4: the quadrature's own
// error there is ~1e-6.
TEST(CameraTest, ImportanceIntegratesToOneOverEachPixel) {
    SensorDescription sensor = tiltedSensor(16, 12, 100.0f, FovAxis::X);
    const PerspectiveCamera camera(sensor);
    const auto direction = [&](double fx, double fy) {
        const Vec3 d = camera.generateRay(float(fx), float(fy)).direction;
        return Imath::V3d(d.x, d.y, d.z);
    };
    const auto triangle = [](const Imath::V3d& a, const Imath::V3d& b, const Imath::V3d& c) {
        const double numerator = std::abs(a.dot(b.cross(c)));
        const double denominator = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
        return 2.0 * std::atan2(numerator, denominator);
    };
    for (const auto& [px, py] : {std::pair{0, 0}, std::pair{8, 6}, std::pair{15, 11}}) {
        constexpr int n = 16;
        double integral = 0.0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const double x0 = px + double(i) / n, x1 = px + double(i + 1) / n;
                const double y0 = py + double(j) / n, y1 = py + double(j + 1) / n;
                const Imath::V3d a = direction(x0, y0), b = direction(x1, y0), c = direction(x1, y1), d = direction(x0, y1);
                const double solidAngle = triangle(a, b, c) + triangle(a, c, d);
                const Vec3 centre = camera.generateRay(float(0.5 * (x0 + x1)), float(0.5 * (y0 + y1))).direction;
                const auto seen = camera.project(camera.position() + centre * 10.0f);
                ASSERT_TRUE(seen);
                EXPECT_EQ(seen->x, px);
                EXPECT_EQ(seen->y, py);
                integral += double(seen->importance) * solidAngle;
            }
        EXPECT_NEAR(integral, 1.0, 1e-4) << "pixel " << px << ", " << py;
    }
}

}  // namespace
}  // namespace vrl
