#include "render/core/distance.h"

#include "render/core/segment_distances.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vrl {

namespace {
using V3d = Imath::V3d;
V3d toDouble(const Vec3& v) { return {v.x, v.y, v.z}; }
}  // namespace

double maxSubtendedAngle(double segmentLength, double h) {
    if (!(h > 0.0)) return M_PI;
    return 2.0 * std::atan(segmentLength / (2.0 * h));
}

double distanceLineSegment(const Vec3& origin, const Vec3& direction, const Vec3& a, const Vec3& b) {
    const V3d d = toDouble(direction);
    const V3d ra = toDouble(a) - toDouble(origin), ab = toDouble(b) - toDouble(a);
    const V3d p = ra - d * d.dot(ra), q = ab - d * d.dot(ab);  // components across the line
    const double qq = q.length2();
    const double s = qq > 0.0 ? std::clamp(-p.dot(q) / qq, 0.0, 1.0) : 0.0;
    return (p + q * s).length();
}

double distanceLineBox(const Vec3& origin, const Vec3& direction, const Imath::Box3f& box) {
    if (box.isEmpty()) return std::numeric_limits<double>::infinity();
    // Does the infinite line pass through the box? (slab test over all t)
    double tNear = -std::numeric_limits<double>::infinity(), tFar = std::numeric_limits<double>::infinity();
    bool crosses = true;
    for (int axis = 0; axis < 3 && crosses; ++axis) {
        const double o = origin[axis], d = direction[axis], lo = box.min[axis], hi = box.max[axis];
        if (d == 0.0) {
            crosses = o >= lo && o <= hi;
        } else {
            double t0 = (lo - o) / d, t1 = (hi - o) / d;
            if (t0 > t1) std::swap(t0, t1);
            tNear = std::max(tNear, t0);
            tFar = std::min(tFar, t1);
            crosses = tNear <= tFar;
        }
    }
    if (crosses) return 0.0;
    // Otherwise the distance, a convex function over the box, is smallest on an edge:
    // the 12 edges in SIMD lanes (distanceLineSegment's arithmetic, bit for bit).
    constexpr size_t kEdges = 12, kSize = kEdges + kSegmentLanesPadding;
    float ends[6][kSize] = {};
    const Vec3 lo = box.min, hi = box.max;
    size_t edge = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (int corner = 0; corner < 4; ++corner, ++edge) {
            Vec3 a, b;
            a[u] = b[u] = (corner & 1) ? hi[u] : lo[u];
            a[v] = b[v] = (corner & 2) ? hi[v] : lo[v];
            a[axis] = lo[axis];
            b[axis] = hi[axis];
            for (int k = 0; k < 3; ++k) ends[k][edge] = a[k], ends[3 + k][edge] = b[k];
        }
    }
    return minDistanceLineSegments(origin, direction, {ends[0], ends[1], ends[2], ends[3], ends[4], ends[5]}, kEdges);
}

double distancePointBox(const Vec3& point, const Imath::Box3f& box) {
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a) {
        const double p = point[a];
        const double gap = std::max({double(box.min[a]) - p, 0.0, p - double(box.max[a])});
        d2 += gap * gap;
    }
    return std::sqrt(d2);
}

double distancePointSegment(const Vec3& point, const Vec3& a, const Vec3& b) {
    const V3d ab = toDouble(b) - toDouble(a), ap = toDouble(point) - toDouble(a);
    const double ll = ab.length2();
    const double s = ll > 0.0 ? std::clamp(ap.dot(ab) / ll, 0.0, 1.0) : 0.0;
    return (ap - ab * s).length();
}

std::pair<double, double> signedDistanceRange(const Imath::Box3f& box, const Vec3& n, const Vec3& x) {
    double centre = 0.0, radius = 0.0;
    for (int a = 0; a < 3; ++a) {
        centre += double(n[a]) * (0.5 * (double(box.min[a]) + double(box.max[a])) - double(x[a]));
        radius += std::abs(double(n[a])) * 0.5 * (double(box.max[a]) - double(box.min[a]));
    }
    return {centre - radius, centre + radius};
}

SegmentBoxDistances distancesSegmentBox(const Vec3& origin, const Vec3& direction, double length,
                                        const Imath::Box3f& box) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    if (box.isEmpty()) return {kInf, kInf};
    const double o[3] = {origin.x, origin.y, origin.z}, d[3] = {direction.x, direction.y, direction.z};
    const double lo[3] = {box.min.x, box.min.y, box.min.z}, hi[3] = {box.max.x, box.max.y, box.max.z};
    // f(t) = squared distance from o + t d to the box: convex, quadratic between slab crossings.
    const auto squared = [&](double t) {
        double sum = 0.0;
        for (int a = 0; a < 3; ++a) {
            const double x = o[a] + t * d[a];
            const double gap = x < lo[a] ? lo[a] - x : x > hi[a] ? x - hi[a] : 0.0;
            sum += gap * gap;
        }
        return sum;
    };
    const auto slope = [&](double t) {  // f'(t) / 2, non-decreasing
        double sum = 0.0;
        for (int a = 0; a < 3; ++a) {
            const double x = o[a] + t * d[a];
            if (x < lo[a]) sum += (x - lo[a]) * d[a];
            else if (x > hi[a]) sum += (x - hi[a]) * d[a];
        }
        return sum;
    };
    double breaks[6];
    int count = 0;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) continue;
        breaks[count++] = (lo[a] - o[a]) / d[a];
        breaks[count++] = (hi[a] - o[a]) / d[a];
    }
    for (int i = 1; i < count; ++i)  // insertion sort of at most 6 (std::sort trips GCC 12's -Warray-bounds here)
        for (int j = i; j > 0 && breaks[j] < breaks[j - 1]; --j) std::swap(breaks[j], breaks[j - 1]);
    // The piece [from, to] holding a minimiser: the first crossing where f' >= 0 ends it.
    int k = 0;
    while (k < count && slope(breaks[k]) < 0.0) ++k;
    const double from = k > 0 ? breaks[k - 1] : -kInf, to = k < count ? breaks[k] : kInf;
    // On it f = A t^2 + B t + C with the axes outside the box at a point inside it (a
    // step of 1 + |end| past a far end, which a step of 1 would not leave in double).
    const double mid = std::isfinite(from) && std::isfinite(to) ? 0.5 * (from + to)
                       : std::isfinite(from)                    ? from + (1.0 + std::abs(from))
                       : std::isfinite(to)                      ? to - (1.0 + std::abs(to))
                                                                : 0.0;
    double A = 0.0, B = 0.0;
    for (int a = 0; a < 3; ++a) {
        const double x = o[a] + mid * d[a];
        if (x < lo[a]) A += d[a] * d[a], B += 2.0 * (o[a] - lo[a]) * d[a];
        else if (x > hi[a]) A += d[a] * d[a], B += 2.0 * (o[a] - hi[a]) * d[a];
    }
    // A = 0: f is constant (0) on the piece, any point of it minimises.
    double best = A > 0.0 ? -B / (2.0 * A) : mid;
    best = std::clamp(best, from, to);
    // Convexity: the nearest point of [0, length] to a minimiser minimises f over it.
    return {std::sqrt(squared(std::min(std::max(best, 0.0), length))), std::sqrt(squared(best))};
}

}  // namespace vrl
