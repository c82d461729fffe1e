// Shared helpers for the statistical tests: Simpson quadrature and Pearson's
// chi-square goodness-of-fit test with its critical value.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

namespace vrl::test {

// Composite Simpson rule on [a, b] with n (even) intervals.
template <class F>
double simpson(F f, double a, double b, int n) {
    const double h = (b - a) / n;
    double sum = f(a) + f(b);
    for (int i = 1; i < n; ++i) sum += f(a + i * h) * (i % 2 ? 4.0 : 2.0);
    return sum * h / 3.0;
}

// Composite 8-point Gauss-Legendre rule on [lo, hi] with `panels` panels; f may
// return any type with + and * double (double, Imath::V3d).
template <class F>
auto gaussLegendre(F f, double lo, double hi, int panels) {
    static constexpr double x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                    0.9602898564975363};
    static constexpr double w[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                    0.1012285362903763};
    decltype(f(lo)) sum = decltype(f(lo))(0);
    const double width = (hi - lo) / panels;
    for (int p = 0; p < panels; ++p) {
        const double mid = lo + (p + 0.5) * width, half = 0.5 * width;
        for (int i = 0; i < 4; ++i) sum += (f(mid - half * x[i]) + f(mid + half * x[i])) * (w[i] * half);
    }
    return sum;
}

// Pearson's statistic, pooling bins (in increasing order of expectation) until
// every pooled bin expects at least 5 samples, as pbrt's Chi2Test does.
struct ChiSquare {
    double statistic = 0;
    int dof = -1;
};
inline ChiSquare chiSquare(const std::vector<double>& observed, const std::vector<double>& expected) {
    std::vector<size_t> order(expected.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });
    ChiSquare result;
    double pooledObs = 0, pooledExp = 0;
    for (size_t i : order) {
        if (expected[i] == 0 && observed[i] > 0) return {std::numeric_limits<double>::infinity(), 1};
        if (expected[i] < 5 || (pooledExp > 0 && pooledExp < 5)) {
            pooledObs += observed[i];
            pooledExp += expected[i];
        } else {
            result.statistic += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
            ++result.dof;
        }
    }
    if (pooledExp > 0) {
        result.statistic += (pooledObs - pooledExp) * (pooledObs - pooledExp) / pooledExp;
        ++result.dof;
    }
    return result;
}

// Upper alpha-quantile of chi-square(dof), Wilson-Hilferty approximation; the
// normal quantile z is found by bisection on erfc.
inline double chiSquareCritical(int dof, double alpha) {
    double lo = 0, hi = 10;  // upper tail 0.5 erfc(z / sqrt 2) decreases in z
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (0.5 * std::erfc(mid / std::sqrt(2.0)) > alpha) lo = mid; else hi = mid;
    }
    const double c = 2.0 / (9.0 * dof);
    return dof * std::pow(1.0 - c + lo * std::sqrt(c), 3);
}

}  // namespace vrl::test
