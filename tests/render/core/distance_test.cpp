// distancesSegmentBox against brute force: the distance from a box to points of
// the segment (and of a long stretch of its line) sampled densely, for random
// boxes and segments, including segments through the box, parallel to a face
// (a zero direction component) and of zero length. The exact minimum can only be
// below the sampled one, and above it by no more than the sampling step (the
// distance is 1-Lipschitz along the line).
// The SIMD minima over many segments (segment_distances.h) against the scalar
// loops they replace, bit for bit.
#include "render/core/distance.h"
#include "render/core/segment_distances.h"

#include "render/core/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

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

// Every count from 0 to 19 (whole SIMD vectors and every remainder), random
// segments around the query, some of zero length, some through the query point or
// on the line; the lanes past `count` hold a segment through the query, which must
// be ignored.
TEST(SegmentLanes, MinimaEqualTheScalarLoopsBitForBit) {
    Rng rng(11, 0);
    const auto coordinate = [&] { return 4.0f * rng.next() - 2.0f; };
    for (int trial = 0; trial < 400; ++trial) {
        const size_t count = size_t(trial % 20);
        const Vec3 point(coordinate(), coordinate(), coordinate());
        const Vec3 direction = Vec3(coordinate(), coordinate(), coordinate()).normalized();
        std::vector<float> lanes[6];
        for (auto& lane : lanes) lane.assign(count + kSegmentLanesPadding, 0.0f);
        for (size_t k = 0; k < count + kSegmentLanesPadding; ++k) {
            Vec3 a(coordinate(), coordinate(), coordinate()), b(coordinate(), coordinate(), coordinate());
            if (k >= count) a = b = point;  // padding: would be the minimum if it were read
            else if (k % 5 == 1) b = a;     // zero length
            else if (k % 7 == 3) a = point; // through the query point
            else if (k % 9 == 4) a = point + direction * 0.5f, b = point - direction * 0.25f;  // on the line
            for (int c = 0; c < 3; ++c) lanes[c][k] = a[c], lanes[3 + c][k] = b[c];
        }
        const SegmentLanes segments{lanes[0].data(), lanes[1].data(), lanes[2].data(),
                                    lanes[3].data(), lanes[4].data(), lanes[5].data()};
        double toPoint = std::numeric_limits<double>::infinity(), toLine = toPoint;
        for (size_t k = 0; k < count; ++k) {
            const Vec3 a(lanes[0][k], lanes[1][k], lanes[2][k]), b(lanes[3][k], lanes[4][k], lanes[5][k]);
            toPoint = std::min(toPoint, distancePointSegment(point, a, b));
            toLine = std::min(toLine, distanceLineSegment(point, direction, a, b));
        }
        EXPECT_EQ(minDistancePointSegments(point, segments, count), toPoint) << trial;
        EXPECT_EQ(minDistanceLineSegments(point, direction, segments, count), toLine) << trial;
    }
}

}  // namespace
}  // namespace vrl
