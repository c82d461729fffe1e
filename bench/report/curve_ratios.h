// Equal-time and equal-error comparisons between error-against-time curves
// (Vibert et al. 2019, Figure 3): a curve is a method's (seconds, error) points
// over its settings; values between points are interpolated linearly in
// log-log space, never extrapolated beyond the measured range.
#pragma once

#include <optional>
#include <vector>

namespace vrl::report {

struct CurvePoint {
    double seconds = 0.0;
    double error = 0.0;
};

// A curve's points sorted by time, keeping only finite, positive values.
std::vector<CurvePoint> cleanCurve(std::vector<CurvePoint> points);

// The curve's error at `seconds` (log-log interpolation between the two
// neighbouring points); empty outside [first, last] time.
std::optional<double> errorAtTime(const std::vector<CurvePoint>& curve, double seconds);

// The earliest time at which the curve reaches `error` or less (interpolating
// log-log on the first segment that crosses it); empty if it never does, and
// empty if its first (cheapest) point is already below `error`: the time is then
// somewhere before the measured range, and a ratio to it would be a guess.
std::optional<double> timeToError(const std::vector<CurvePoint>& curve, double error);

}  // namespace vrl::report
