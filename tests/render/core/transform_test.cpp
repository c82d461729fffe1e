// Transform composition and conventions (Mitsuba's XML order, lookat, matrix).
#include "render/core/transform.h"

#include <gtest/gtest.h>

namespace vrl {
namespace {

void expectVec(const Vec3& a, const Vec3& b, float tol = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

TEST(Transform, RotateIsRightHanded) {
    expectVec(Transform::rotate(Vec3(0, 0, 1), 90).applyPoint(Vec3(1, 0, 0)), Vec3(0, 1, 0));
    expectVec(Transform::rotate(Vec3(1, 0, 0), 90).applyPoint(Vec3(0, 1, 0)), Vec3(0, 0, 1));
}

TEST(Transform, ThenAppliesInOrder) {
    // translate then rotate: (1,0,0) -> (2,0,0) -> (0,2,0)
    const Transform t = Transform::translate(Vec3(1, 0, 0)).then(Transform::rotate(Vec3(0, 0, 1), 90));
    expectVec(t.applyPoint(Vec3(1, 0, 0)), Vec3(0, 2, 0));
    // vectors ignore the translation
    expectVec(t.applyVector(Vec3(1, 0, 0)), Vec3(0, 1, 0));
}

TEST(Transform, RowMajorMatrixIsColumnVectorConvention) {
    const Transform t = Transform::fromRowMajor({1, 0, 0, 5, 0, 1, 0, 6, 0, 0, 1, 7, 0, 0, 0, 1});
    expectVec(t.applyPoint(Vec3(1, 1, 1)), Vec3(6, 7, 8));
    const auto back = t.toRowMajor();
    EXPECT_DOUBLE_EQ(back[3], 5.0);
    EXPECT_DOUBLE_EQ(back[11], 7.0);
}

TEST(Transform, LookAtPointsZAtTargetAndXLeft) {
    const Transform t = Transform::lookAt(Vec3(0, 0, -5), Vec3(0, 0, 0), Vec3(0, 1, 0));
    expectVec(t.applyPoint(Vec3(0, 0, 0)), Vec3(0, 0, -5));
    expectVec(t.applyVector(Vec3(0, 0, 1)), Vec3(0, 0, 1));
    expectVec(t.applyVector(Vec3(0, 1, 0)), Vec3(0, 1, 0));
    expectVec(t.applyVector(Vec3(1, 0, 0)), Vec3(1, 0, 0));  // up x dir = y x z = x ("left" in Mitsuba's image)
    EXPECT_THROW(Transform::lookAt(Vec3(1, 1, 1), Vec3(1, 1, 1), Vec3(0, 1, 0)), std::invalid_argument);
    EXPECT_THROW(Transform::lookAt(Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(0, 1, 0)), std::invalid_argument);
}

TEST(Transform, NormalsUseInverseTranspose) {
    const Transform t = Transform::scale(Vec3(2, 1, 1));
    // The plane x + y = 0 has normal (1,1,0); after scaling x by 2 its normal is (0.5,1,0).
    const Vec3 n = t.applyNormal(Vec3(1, 1, 0)).normalized();
    expectVec(n, Vec3(0.5f, 1, 0).normalized());
    EXPECT_FALSE(t.flipsHandedness());
    EXPECT_TRUE(Transform::scale(Vec3(-1, 1, 1)).flipsHandedness());
}

TEST(Transform, InverseUndoes) {
    const Transform t = Transform::rotate(Vec3(1, 2, 3), 33).then(Transform::translate(Vec3(4, -1, 2)));
    expectVec(t.inverse().applyPoint(t.applyPoint(Vec3(0.3f, -0.7f, 2))), Vec3(0.3f, -0.7f, 2), 1e-4f);
}

}  // namespace
}  // namespace vrl
