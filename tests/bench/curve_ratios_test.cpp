// Equal-time / equal-error interpolation of the benchmark report.
#include "bench/report/curve_ratios.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace vrl::report;

TEST(CurveRatios, CleanDropsBadPointsAndSortsByTime) {
    const auto c = cleanCurve({{4, 1}, {1, 8}, {0, 1}, {2, NAN}, {-1, 1}, {2, 0}, {INFINITY, 1}, {2, 3}});
    ASSERT_EQ(c.size(), 3u);
    EXPECT_EQ(c[0].seconds, 1);
    EXPECT_EQ(c[1].seconds, 2);
    EXPECT_EQ(c[2].seconds, 4);
}

TEST(CurveRatios, ErrorAtTimeInterpolatesLogLog) {
    // error = 8 / t on [1, 4]: a straight line in log-log space.
    const auto c = cleanCurve({{1, 8}, {4, 2}});
    EXPECT_NEAR(*errorAtTime(c, 2.0), 4.0, 1e-12);
    EXPECT_NEAR(*errorAtTime(c, 1.0), 8.0, 1e-12);
    EXPECT_NEAR(*errorAtTime(c, 4.0), 2.0, 1e-12);
    EXPECT_FALSE(errorAtTime(c, 0.5));  // never extrapolated
    EXPECT_FALSE(errorAtTime(c, 5.0));
    EXPECT_FALSE(errorAtTime({}, 1.0));
}

TEST(CurveRatios, TimeToErrorTakesTheFirstCrossing) {
    const auto c = cleanCurve({{1, 8}, {4, 2}, {16, 4}, {64, 0.5}});
    EXPECT_NEAR(*timeToError(c, 4.0), 2.0, 1e-12);
    EXPECT_NEAR(*timeToError(c, 8.0), 1.0, 1e-12);   // already at the first point
    // Between (16, 4) and (64, 0.5): 1 is 2/3 of the way in log error, so t = 16 * 4^(2/3).
    EXPECT_NEAR(*timeToError(c, 1.0), 16.0 * std::pow(4.0, 2.0 / 3.0), 1e-9);
    EXPECT_FALSE(timeToError(c, 0.25));               // never reached
    EXPECT_FALSE(timeToError(c, 9.0));                // reached before the first point: never extrapolated
}
