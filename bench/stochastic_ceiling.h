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
// takes K M >= (sum_i s_i)^2 / sum_i s_i^2, so on one segment the cut saves at most
//   N sum_i s_i^2 / (sum_i s_i)^2 = N / N_eff
// of plain's N estimates, N_eff being the participation ratio of the VRLs' noise
// (N when every VRL is equally noisy, 1 when one VRL holds all of it). In time the
// saving is smaller by the ratio of costs per estimate: vrl-stochastic runs plain's
// kernel for each drawn VRL plus its importances (measured by the bench).
// Over an image, relRMSE weights pixel p's squared error by w_p = 1 / (ref_p^2 + eps),
// and a pixel's camera segments are independent. If the cut spends n_g = K_g M_g
// estimates on segment g (of pixel p), the image's weighted variance is at least
// sum_g w_p S_g^2 / n_g (S_g = sum_i s_i on g). Over budgets n_g of total B this is
// smallest for n_g ~ sqrt(w_p) S_g (Cauchy-Schwarz): (sum_g sqrt(w_p) S_g)^2 / B.
// Plain VRLs spend N per segment, N G in all (G segments), for sum_g w_p P_g
// (P_g = sum_i s_i^2 on g). So any cut that matches plain's error saves at most
//   N G sum_g w_p P_g / (sum_g sqrt(w_p) S_g)^2                          (ceiling)
// and one with the same K M on every segment, as vrl-stochastic, at most
//   N sum_g w_p P_g / sum_g w_p S_g^2                                      (uniformCeiling)
// (no larger than the first, by Cauchy-Schwarz). Assumed: each drawn VRL's estimate
// is plain's one-sample estimator (or an average of V of them at V times the cost:
// the same bound per (u, v) sample), and each segment is fixed. A camera path with
// a random specular choice (glass) is not: M samples of a method average that
// choice, plain's one path does not, so such pixels are left out of the sums.
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

// The per-segment terms summed over an image, each segment with its pixel's weight.
struct CeilingSums {
    double plain = 0.0;    // sum_g w P_g: plain's weighted variance
    double root = 0.0;     // sum_g sqrt(w) S_g
    double uniform = 0.0;  // sum_g w S_g^2
    double segments = 0.0;  // G
    void add(std::span<const EstimateMoments> vrls, double weight) {
        double p = 0.0, deviations = 0.0;
        for (const EstimateMoments& m : vrls) {
            const double d = m.deviation();
            p += d * d, deviations += d;
        }
        plain += weight * p, root += std::sqrt(weight) * deviations, uniform += weight * deviations * deviations;
        segments += 1.0;
    }
    void add(const CeilingSums& o) {
        plain += o.plain, root += o.root, uniform += o.uniform, segments += o.segments;
    }
    // The most plain estimates one estimate of any stochastic cut can stand for (N
    // VRLs per segment), with its estimates spread over the segments at will.
    double ceiling(size_t vrlCount) const {
        return root > 0.0 ? double(vrlCount) * segments * plain / (root * root) : 0.0;
    }
    // The same with K M estimates on every segment.
    double uniformCeiling(size_t vrlCount) const { return uniform > 0.0 ? double(vrlCount) * plain / uniform : 0.0; }
};

}  // namespace vrl::bench
