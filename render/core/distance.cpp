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
    // Slab crossings: where a coordinate of the line meets a face plane.
    double breaks[6];
    int count = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const double d = direction[axis];
        if (d == 0.0) continue;
        breaks[count++] = (double(box.min[axis]) - double(origin[axis])) / d;
        breaks[count++] = (double(box.max[axis]) - double(origin[axis])) / d;
    }
    for (int i = 1; i < count; ++i)  // insertion sort of at most 6 (std::sort trips GCC 12's -Warray-bounds here)
        for (int j = i; j > 0 && breaks[j] < breaks[j - 1]; --j) std::swap(breaks[j], breaks[j - 1]);
    // The squared distance on the piece containing t: sum over axes of (outside gap)^2,
    // each gap linear in t on the piece: A t^2 + B t + C.
    const auto pieceMinimum = [&](double a, double b) {  // min over [a, b] of the piece around (a + b) / 2
        const double mid = std::isfinite(a) && std::isfinite(b) ? 0.5 * (a + b) : std::isfinite(a) ? a + 1.0 : b - 1.0;
        double A = 0.0, B = 0.0, C = 0.0;
        for (int axis = 0; axis < 3; ++axis) {
            const double o = origin[axis], d = direction[axis], lo = box.min[axis], hi = box.max[axis];
            const double x = o + mid * d;
            double p0, p1;  // gap = p0 + p1 t
            if (x < lo) p0 = lo - o, p1 = -d;
            else if (x > hi) p0 = o - hi, p1 = d;
            else continue;
            A += p1 * p1, B += 2.0 * p0 * p1, C += p0 * p0;
        }
        const auto value = [&](double t) { return std::max(0.0, (A * t + B) * t + C); };
        double best = kInf;
        if (std::isfinite(a)) best = std::min(best, value(a));
        if (std::isfinite(b)) best = std::min(best, value(b));
        if (A > 0.0) {
            const double t = -B / (2.0 * A);
            if (t >= a && t <= b) best = std::min(best, value(t));
        } else if (!std::isfinite(a) || !std::isfinite(b)) {
            best = std::min(best, C);  // constant on an unbounded piece (B = 0 when A = 0)
        }
        return best;
    };
    double line = kInf, segment = kInf;
    double from = -kInf;
    for (int k = 0; k <= count; ++k) {
        const double to = k < count ? breaks[k] : kInf;
        if (to >= from) {
            line = std::min(line, pieceMinimum(from, to));
            const double a = std::max(from, 0.0), b = std::min(to, length);
            if (a <= b) segment = std::min(segment, pieceMinimum(a, b));
        }
        from = to;
    }
    return {std::sqrt(segment), std::sqrt(line)};
}

}  // namespace vrl
