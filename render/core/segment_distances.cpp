// Line- and point-to-segments distances in double lanes (contract: segment_distances.h).

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/core/segment_distances.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "render/core/segment_distances.h"

#include <cmath>
#include <limits>

HWY_BEFORE_NAMESPACE();
namespace vrl {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Imath's dot product order: (x x' + y y') + z z'.
template <class V>
HWY_INLINE V Dot3(V ax, V ay, V az, V bx, V by, V bz) {
    return hn::Add(hn::Add(hn::Mul(ax, bx), hn::Mul(ay, by)), hn::Mul(az, bz));
}

// The smallest over segments k < count of what `distance` gives for their ends
// (double lanes, promoted from the float arrays); lanes past count are ignored.
template <class D, class Distance>
HWY_INLINE double MinOverSegments(D dd, const SegmentLanes& s, size_t count, const Distance& distance) {
    const hn::Rebind<float, D> df;
    auto best = hn::Set(dd, std::numeric_limits<double>::infinity());
    const size_t lanes = hn::Lanes(dd);
    for (size_t i = 0; i < count; i += lanes) {
        const auto load = [&](const float* p) { return hn::PromoteTo(dd, hn::LoadU(df, p + i)); };
        const auto value = distance(load(s.ax), load(s.ay), load(s.az), load(s.bx), load(s.by), load(s.bz));
        best = hn::IfThenElse(hn::FirstN(dd, count - i), hn::Min(best, value), best);
    }
    return hn::GetLane(hn::MinOfLanes(dd, best));
}

double MinDistanceLineSegments(const Vec3& origin, const Vec3& direction, const SegmentLanes& s, size_t count) {
    const hn::ScalableTag<double> dd;
    using V = hn::Vec<decltype(dd)>;
    const V dx = hn::Set(dd, double(direction.x)), dy = hn::Set(dd, double(direction.y)), dz = hn::Set(dd, double(direction.z));
    const V ox = hn::Set(dd, double(origin.x)), oy = hn::Set(dd, double(origin.y)), oz = hn::Set(dd, double(origin.z));
    const V zero = hn::Zero(dd), one = hn::Set(dd, 1.0);
    return MinOverSegments(dd, s, count, [&](V ax, V ay, V az, V bx, V by, V bz) {
        // distanceLineSegment: ra = a - origin, ab = b - a, p and q their parts across the line.
        const V rax = hn::Sub(ax, ox), ray = hn::Sub(ay, oy), raz = hn::Sub(az, oz);
        const V abx = hn::Sub(bx, ax), aby = hn::Sub(by, ay), abz = hn::Sub(bz, az);
        const V dra = Dot3(dx, dy, dz, rax, ray, raz), dab = Dot3(dx, dy, dz, abx, aby, abz);
        const V px = hn::Sub(rax, hn::Mul(dx, dra)), py = hn::Sub(ray, hn::Mul(dy, dra)), pz = hn::Sub(raz, hn::Mul(dz, dra));
        const V qx = hn::Sub(abx, hn::Mul(dx, dab)), qy = hn::Sub(aby, hn::Mul(dy, dab)), qz = hn::Sub(abz, hn::Mul(dz, dab));
        const V qq = Dot3(qx, qy, qz, qx, qy, qz);
        const auto degenerate = hn::Le(qq, zero);
        const V t = hn::Div(hn::Neg(Dot3(px, py, pz, qx, qy, qz)), hn::IfThenElse(degenerate, one, qq));
        const V sClamped = hn::IfThenZeroElse(degenerate, hn::Min(hn::Max(t, zero), one));
        const V cx = hn::Add(px, hn::Mul(qx, sClamped)), cy = hn::Add(py, hn::Mul(qy, sClamped)),
                cz = hn::Add(pz, hn::Mul(qz, sClamped));
        return hn::Sqrt(Dot3(cx, cy, cz, cx, cy, cz));
    });
}

double MinDistancePointSegments(const Vec3& point, const SegmentLanes& s, size_t count) {
    const hn::ScalableTag<double> dd;
    using V = hn::Vec<decltype(dd)>;
    const V px = hn::Set(dd, double(point.x)), py = hn::Set(dd, double(point.y)), pz = hn::Set(dd, double(point.z));
    const V zero = hn::Zero(dd), one = hn::Set(dd, 1.0);
    // The smallest squared distance: sqrt is monotone and correctly rounded, so the
    // square root of the minimum is the minimum of the scalar loop's square roots.
    return std::sqrt(MinOverSegments(dd, s, count, [&](V ax, V ay, V az, V bx, V by, V bz) {
        // distancePointSegment: ab = b - a, ap = point - a, s = clamp(ap.ab / ab.ab, 0, 1).
        const V abx = hn::Sub(bx, ax), aby = hn::Sub(by, ay), abz = hn::Sub(bz, az);
        const V apx = hn::Sub(px, ax), apy = hn::Sub(py, ay), apz = hn::Sub(pz, az);
        const V ll = Dot3(abx, aby, abz, abx, aby, abz);
        const auto degenerate = hn::Not(hn::Gt(ll, zero));
        const V t = hn::Div(Dot3(apx, apy, apz, abx, aby, abz), hn::IfThenElse(degenerate, one, ll));
        const V sClamped = hn::IfThenZeroElse(degenerate, hn::Min(hn::Max(t, zero), one));
        const V cx = hn::Sub(apx, hn::Mul(abx, sClamped)), cy = hn::Sub(apy, hn::Mul(aby, sClamped)),
                cz = hn::Sub(apz, hn::Mul(abz, sClamped));
        return Dot3(cx, cy, cz, cx, cy, cz);
    }));
}

}  // namespace HWY_NAMESPACE
}  // namespace vrl
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace vrl {

HWY_EXPORT(MinDistanceLineSegments);

double minDistanceLineSegments(const Vec3& origin, const Vec3& direction, const SegmentLanes& segments, size_t count) {
    return HWY_DYNAMIC_DISPATCH(MinDistanceLineSegments)(origin, direction, segments, count);
}

HWY_EXPORT(MinDistancePointSegments);

double minDistancePointSegments(const Vec3& point, const SegmentLanes& segments, size_t count) {
    return HWY_DYNAMIC_DISPATCH(MinDistancePointSegments)(point, segments, count);
}

}  // namespace vrl
#endif
