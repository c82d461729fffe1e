// InterleavedPoints: part (c) (VRL-lit surfaces) over several surface points of
// one pixel for about the price of one.
//
// Why: (c) is evaluated once per pixel (transport_integrator.h), at one camera
// ray jittered over the pixel, while the path-sampled parts average spp rays.
// Where the pixel holds an edge (a stair's nosing, a railing in front of a wall)
// the one point lands on either side, and the pixel's (c) jumps between seeds; on
// scenes with many edges (staircase at its own resolution) that is most of (c)'s
// noise (docs/measurements/2026-12-07-tuning-constants.md).
// Evaluating every VRL (or cut) at each of Q points would cost Q times as much.
//
// Contract: Q points x_0..x_{Q-1} (one per stratum of the pixel, any of them
// absent where the camera path has no (c): escaped, an emitter, a depth limit),
// and an offset o drawn uniformly from {0, ..., Q-1}, independent of the points.
// Light k (a VRL, by its index; a cut node, by its representative's) is
// evaluated at x_{(k + o) mod Q} only, an absent point contributing 0:
//   I = sum_k L_k(x_{(k + o) mod Q}).
// Derivation (unbiased for the pixel's mean): for each k, (k + o) mod Q is
// uniform over {0, ..., Q-1} whatever k is, so
//   E_o[I] = sum_k (1/Q) sum_q L_k(x_q) = (1/Q) sum_q L(x_q),
// the mean over the Q points of the whole (c), and with stratified points the
// expectation over their jitter is the pixel's mean (the path tracer's
// estimand). The variance: each point receives about 1/Q of the lights (one
// residue class of the index: an even spread, since consecutive VRLs are
// consecutive pieces of one light path, close in space), so a pixel half on each
// side of an edge gets half its lights from each side instead of all from one.
// Exactly so for the plain sum and for a cut at threshold 0 (every VRL reached).
// A cut (surface_lightcuts_estimator.h) estimates each node at its representative's point; a
// node and the child that shares its representative are then evaluated at the same
// point, as the walk's inherited estimates require (cut_walk.h). Its bound is the
// largest of its bounds at the points: each is Phi_C times the most a unit of flux
// anywhere in the box gives that point, so the maximum bounds
// sum_{k in C} L_k(x_{(k + o) mod Q}) wherever each VRL goes, and the cut keeps its
// proven error control. That costs one bound per node and point (staircase's render
// took 1.8 times as long with every pixel interleaved over four), and where points
// lie on one flat piece of one shape they differ by little but their texels. So the
// integrator (transport_integrator.cpp) groups the points into classes of such
// points and lets one point of each class, drawn uniformly from it independently of
// o, stand for the whole class: entry q of `points` then holds the representative
// r(c(q)) of q's class, the same pointer at several entries (a representative takes
// its textures' mean over its class's strata: pixel_footprint.h). Unbiased still: for
// each k, q = (k + o) mod Q is uniform, so the class c is drawn with probability
// n_c / Q, and the representative is uniform within it,
//   E[L_k(r(c(q)))] = sum_c (n_c / Q) (1 / n_c) sum_{q' in c} L_k(x_q') = (1/Q) sum_q L_k(x_q).
// (Exactly so without textures. With them, the representative's lookups are its
// class's mean, so the expectation takes each point's light with its class's mean
// texture: the approximation pixel_footprint.h makes for the whole pixel, over a
// class's quarters instead of one quarter; they differ by the covariance of light
// and texture inside the class.)
// The cut then bounds each node at the representatives only (distinct()): an edge
// between two surfaces pays two bounds, not four, and one class (with points
// absent) pays the one point's own bound, which holds for any subset of the VRLs.
// Where all Q points are one class the integrator takes point x_o alone, whose
// expectation over o is the same mean, at the price of one cut. With a threshold the
// cut depends on o (through the running total), and the image carries the cut's
// approximation as any Lightcuts image does, measured against the plain
// interleaved sum (Lightcuts.SurfaceErrorShrinksWithThresholdJitteredInLitRoom).
// Q = 1 is the single point, bit for bit.
#pragma once

#include "render/vrl/camera_segment.h"

#include <array>
#include <cstdint>

namespace vrl {

// Part (c)'s interleaved points per side of a pixel (or of a shading point's stratum).
inline constexpr int kInterleavedPointsSide = 2;

struct InterleavedPoints {
    static constexpr uint32_t kMaxPoints = uint32_t(kInterleavedPointsSide * kInterleavedPointsSide);
    std::array<const CameraPathSurface*, kMaxPoints> points{};  // null: that point has no (c)
    uint32_t count = 1;   // Q, in [1, kMaxPoints]
    uint32_t offset = 0;  // o, in [0, count)

    static InterleavedPoints single(const CameraPathSurface& x) {
        InterleavedPoints p;
        p.points[0] = &x;
        return p;
    }
    // The point light `index` (a VRL's index in the tree's order) is evaluated at; null: none.
    const CameraPathSurface* at(uint32_t index) const { return points[(index + offset) % count]; }
    // The different points present (several entries may hold one point: a class's
    // representative), in order of first appearance; returns how many.
    uint32_t distinct(std::array<const CameraPathSurface*, kMaxPoints>& out) const {
        uint32_t n = 0;
        for (uint32_t q = 0; q < count; ++q) {
            const CameraPathSurface* p = points[q];
            if (!p) continue;
            bool seen = false;
            for (uint32_t j = 0; j < n && !seen; ++j) seen = out[j] == p;
            if (!seen) out[n++] = p;
        }
        return n;
    }
};

}  // namespace vrl
