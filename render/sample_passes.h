// Sample passes: the order in which a pixel's camera samples are taken and
// summed, one definition for fixed and progressive renders.
//
// Pass p holds samples [2^p - 1, 2^(p+1) - 1) of every pixel (1, 2, 4, ...
// samples), cut at the render's sample cap. A pixel's sum over its first P
// passes is, by definition, the fold ((B_0 + B_1) + B_2) + ... of the passes'
// own sums B_p (each summed in sample order from zero), so:
//   - a fixed render of N samples shades passes [0, passesFor(N)) and folds
//     them, and a progressive render that stops after P whole passes holds
//     exactly the sums of a fixed render of samplesAfter(P, N) samples, bit for bit;
//   - the service may shade pass p of a tile anywhere and add it to the
//     tile's sum of passes [0, p) (sample_sums.h, server/tile_passes.h).
// Camera sample s of a pixel draws from its own random stream, keyed by
// (seed, film pixel, s) (renderer.h), so no sample depends on those before it.
#pragma once

#include <algorithm>
#include <cstdint>

namespace vrl {

// Passes that a sample count needs: 2^20 samples (kMaxSampleCount) take 21.
inline constexpr int kMaxPasses = 31;

// Samples [first, first + count) of every pixel.
struct SamplePass {
    int first = 0, count = 0;
};

// Pass `pass` of a render capped at `sampleCap` samples per pixel (count 0: past the cap).
constexpr SamplePass samplePass(int pass, int sampleCap) {
    if (pass < 0 || pass >= kMaxPasses) return {sampleCap, 0};
    const int64_t first = (int64_t(1) << pass) - 1, end = (int64_t(1) << (pass + 1)) - 1;
    const int64_t cap = std::max(0, sampleCap);
    return {int(std::min(first, cap)), int(std::max<int64_t>(0, std::min(end, cap) - std::min(first, cap)))};
}

// Samples per pixel after the first `passes` passes: min(2^passes - 1, sampleCap).
constexpr int samplesAfter(int passes, int sampleCap) {
    if (passes <= 0) return 0;
    if (passes >= kMaxPasses) return sampleCap;
    return int(std::min<int64_t>((int64_t(1) << passes) - 1, std::max(0, sampleCap)));
}

// The passes that hold `samples` samples: the least P with 2^P - 1 >= samples.
constexpr int passesFor(int samples) {
    int passes = 0;
    while (passes < kMaxPasses && samplesAfter(passes, samples) < samples) ++passes;
    return passes;
}

}  // namespace vrl
