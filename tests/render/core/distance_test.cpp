// distancesSegmentBox against brute force: the distance from a box to points of
// the segment (and of a long stretch of its line) sampled densely, for random
// boxes and segments, including segments through the box, parallel to a face
// (a zero direction component) and of zero length. The exact minimum can only be
// below the sampled one, and above it by no more than the sampling step (the
// distance is 1-Lipschitz along the line).
#include "render/core/distance.h"

#include "render/core/rng.h"

#include <gtest/gtest.h>

#include <cmath>

namespace vrl {
namespace {

double sampledMinimum(const Vec3& o, const Vec3& d, double from, double to, const Imath::Box3f& box, int steps,
                      double& step) {
    step = (to - from) / steps;
    double best = 1e300;
    for (int i = 0; i <= steps; ++i) best = std::min(best, distancePointBox(o + d * float(from + i * step), box));
    return best;
}

TEST(DistancesSegmentBox, MatchBruteForce) {
    Rng rng(7, 0);
    const auto coordinate = [&] { return 4.0f * rng.next() - 2.0f; };
    for (int trial = 0; trial < 3000; ++trial) {
        Imath::Box3f box;
        box.extendBy(Imath::V3f(coordinate(), coordinate(), coordinate()));
        box.extendBy(Imath::V3f(coordinate(), coordinate(), coordinate()));
        const Vec3 o(coordinate(), coordinate(), coordinate());
        Vec3 d(coordinate(), coordinate(), coordinate());
        if (trial % 5 == 1) d[trial % 3] = 0.0f;  // parallel to a pair of faces
        if (trial % 7 == 2) d[(trial + 1) % 3] = 0.0f, d[trial % 3] = 0.0f;  // along an axis
        d = d.normalized();
        const double length = trial % 11 == 3 ? 0.0 : 3.0 * rng.next();
        const SegmentBoxDistances exact = distancesSegmentBox(o, d, length, box);
        double step = 0.0;
        const double segment = sampledMinimum(o, d, 0.0, length, box, 4000, step);
        EXPECT_LE(exact.segment, segment + 1e-6) << trial;
        EXPECT_GE(exact.segment, segment - step - 1e-6) << trial;
        const double line = sampledMinimum(o, d, -20.0, 20.0, box, 40000, step);
        EXPECT_LE(exact.line, line + 1e-6) << trial;
        EXPECT_GE(exact.line, line - step - 1e-6) << trial;
        EXPECT_LE(exact.line, exact.segment + 1e-9) << trial;
    }
    // Through the box: both 0; an empty box: infinitely far.
    const Imath::Box3f unit(Imath::V3f(0.0f), Imath::V3f(1.0f));
    EXPECT_EQ(distancesSegmentBox(Vec3(-1.0f, 0.5f, 0.5f), Vec3(1.0f, 0.0f, 0.0f), 3.0, unit).segment, 0.0);
    EXPECT_NEAR(distancesSegmentBox(Vec3(-3.0f, 0.5f, 0.5f), Vec3(1.0f, 0.0f, 0.0f), 1.0, unit).segment, 2.0, 1e-12);
    EXPECT_EQ(distancesSegmentBox(Vec3(-3.0f, 0.5f, 0.5f), Vec3(1.0f, 0.0f, 0.0f), 1.0, unit).line, 0.0);
    EXPECT_TRUE(std::isinf(distancesSegmentBox(Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f), 1.0, Imath::Box3f()).segment));
}

}  // namespace
}  // namespace vrl
