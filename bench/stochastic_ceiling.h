// StochasticCeiling: how far any stochastic cut can get ahead of plain VRLs at
// equal error, from the moments of the one-VRL estimates (stochastic_bench
// --ceiling). Pure arithmetic; the bench measures the moments.
//
// Setting. For one camera segment, VRL i's one-sample estimate X_i (the same
// estimator plain VRLs sum) has mean c_i >= 0, second moment m_i = E[X_i^2] and
// variance s_i^2 = m_i - c_i^2. Plain VRLs return sum_i X_i: variance sum_i s_i^2,
// N estimates. A stochastic cut of K nodes draws, under node n, one VRL i with
// probability q_i (sum over the node's VRLs: 1) and returns X_i / q_i, the nodes
// independently. One node's variance is
//   V_n(q) = sum_{i in n} m_i / q_i - C_n^2,   C_n = sum_{i in n} c_i       (nodeVariance)
// and by Cauchy-Schwarz it is smallest for q_i ~ a_i = sqrt(m_i):
//   V_n >= A_n^2 - C_n^2,   A_n = sum_{i in n} a_i                         (idealNodeVariance)
// The ceiling. (A, C) -> sqrt(A^2 - C^2) is the Lorentzian norm, and each (a_i, c_i)
// lies in its forward cone (a_i >= c_i >= 0), where the triangle inequality holds
// reversed: sqrt(A_n^2 - C_n^2) >= sum_{i in n} sqrt(a_i^2 - c_i^2) = sum_{i in n} s_i.
// With Cauchy-Schwarz over the K nodes, K sum_n V_n >= (sum_n sqrt(V_n))^2 >=
// (sum_i s_i)^2, whatever the cut, the partition and the probabilities. M samples of
// the cut (K M estimates) have variance sum_n V_n / M; matching plain's sum_i s_i^2
// takes K M >= (sum_i s_i)^2 / sum_i s_i^2, so the cut saves at most
//   N sum_i s_i^2 / (sum_i s_i)^2 = N / N_eff                                (ceiling)
// of plain's N estimates, N_eff being the participation ratio of the VRLs' noise
// (N when every VRL is equally noisy, 1 when one VRL holds all of it). Each
// stochastic estimate costs at least what a plain one does (the same kernel,
// plus importances), so N / N_eff also caps the speed-up in time. It holds for
// (u, v) samples too: V samples per drawn VRL divide each s_i^2 by V and multiply
// the cost by V.
// Over an image, the error that relRMSE measures weights pixel p by
// w_p = 1 / (mean_p^2 + eps) and every pixel gets the same M: the ceiling is
// N sum_p w_p sum_i s_i^2 / sum_p w_p (sum_i s_i)^2 (CeilingSums).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>

namespace vrl::bench {

struct EstimateMoments {
    double mean = 0.0;    // c_i
    double second = 0.0;  // m_i = E[X_i^2] >= c_i^2
    double deviation() const { return std::sqrt(std::max(0.0, second - mean * mean)); }  // s_i
};

// V_n(q): the variance of one draw under a node (q[k] the probability of leaves[k];
// infinite if a leaf with m > 0 has q = 0: that leaf's contribution is never seen).
inline double nodeVariance(std::span<const EstimateMoments> leaves, std::span<const double> probabilities) {
    double sum = 0.0, mean = 0.0;
    for (size_t k = 0; k < leaves.size(); ++k) {
        mean += leaves[k].mean;
        if (leaves[k].second <= 0.0) continue;
        if (!(probabilities[k] > 0.0)) return std::numeric_limits<double>::infinity();
        sum += leaves[k].second / probabilities[k];
    }
    return sum - mean * mean;
}

// A_n^2 - C_n^2: the smallest V_n over all probabilities (q_i ~ sqrt(m_i)).
inline double idealNodeVariance(std::span<const EstimateMoments> leaves) {
    double a = 0.0, mean = 0.0;
    for (const EstimateMoments& m : leaves) a += std::sqrt(std::max(0.0, m.second)), mean += m.mean;
    return a * a - mean * mean;
}

// Per-segment terms summed over a region (an image), each with its pixel's weight.
struct CeilingSums {
    double noise = 0.0;      // sum w sum_i s_i^2: plain's variance
    double noiseSum2 = 0.0;  // sum w (sum_i s_i)^2: K M times the least variance of any cut
    void add(std::span<const EstimateMoments> vrls, double weight) {
        double s2 = 0.0, s = 0.0;
        for (const EstimateMoments& m : vrls) {
            const double d = m.deviation();
            s2 += d * d, s += d;
        }
        noise += weight * s2, noiseSum2 += weight * s * s;
    }
    // N / N_eff: the most plain estimates one stochastic estimate can stand for.
    double ceiling(size_t vrlCount) const { return noiseSum2 > 0.0 ? double(vrlCount) * noise / noiseSum2 : 0.0; }
};

}  // namespace vrl::bench
