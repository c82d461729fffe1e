#include "bench/report/curve_ratios.h"

#include <algorithm>
#include <cmath>

namespace vrl::report {

std::vector<CurvePoint> cleanCurve(std::vector<CurvePoint> points) {
    std::erase_if(points, [](const CurvePoint& p) {
        return !(std::isfinite(p.seconds) && p.seconds > 0.0 && std::isfinite(p.error) && p.error > 0.0);
    });
    std::sort(points.begin(), points.end(), [](const CurvePoint& a, const CurvePoint& b) {
        return a.seconds != b.seconds ? a.seconds < b.seconds : a.error < b.error;
    });
    return points;
}

std::optional<double> errorAtTime(const std::vector<CurvePoint>& curve, double seconds) {
    if (curve.empty() || !(seconds > 0.0) || seconds < curve.front().seconds || seconds > curve.back().seconds)
        return std::nullopt;
    for (size_t i = 0; i + 1 < curve.size(); ++i) {
        const CurvePoint &a = curve[i], &b = curve[i + 1];
        if (seconds < a.seconds || seconds > b.seconds) continue;
        if (b.seconds == a.seconds) return std::min(a.error, b.error);
        const double s = (std::log(seconds) - std::log(a.seconds)) / (std::log(b.seconds) - std::log(a.seconds));
        return std::exp(std::log(a.error) + s * (std::log(b.error) - std::log(a.error)));
    }
    return curve.front().error;  // a single point at exactly this time
}

std::optional<double> timeToError(const std::vector<CurvePoint>& curve, double error) {
    if (curve.empty() || !(error > 0.0)) return std::nullopt;
    if (curve.front().error == error) return curve.front().seconds;
    if (curve.front().error < error) return std::nullopt;  // reached before the first point: not measured
    for (size_t i = 0; i + 1 < curve.size(); ++i) {
        const CurvePoint &a = curve[i], &b = curve[i + 1];
        if (!(b.error <= error)) continue;  // a.error > error >= b.error: the first crossing
        const double s = (std::log(error) - std::log(a.error)) / (std::log(b.error) - std::log(a.error));
        return std::exp(std::log(a.seconds) + s * (std::log(b.seconds) - std::log(a.seconds)));
    }
    return std::nullopt;
}

}  // namespace vrl::report
