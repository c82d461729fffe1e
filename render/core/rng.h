// Rng: PCG32 (O'Neill 2014) random stream. Every stream in the renderer is
// created from an explicit (seed, stream index) pair, e.g. (job seed, pixel) or
// (job seed, light path index), so results never depend on thread scheduling.
#pragma once

#include <cstdint>

namespace vrl {

class Rng {
public:
    Rng(uint64_t seed, uint64_t stream) {
        inc_ = (mix(stream) << 1u) | 1u;
        state_ = 0;
        nextUint();
        state_ += mix(seed ^ 0x853c49e6748fea9bULL);
        nextUint();
    }

    uint32_t nextUint() {
        const uint64_t old = state_;
        state_ = old * 6364136223846793005ULL + inc_;
        const auto xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
        const auto rot = static_cast<uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
    }

    // Uniform float in [0, 1).
    float next() { return static_cast<float>(nextUint() >> 8) * 0x1p-24f; }
    // Uniform double in [0, 1) with 53 random bits.
    double nextDouble() {
        const uint64_t hi = nextUint() >> 5, lo = nextUint() >> 6;
        return static_cast<double>((hi << 26) | lo) * 0x1p-53;
    }

    // Combines two 64-bit values into a stream index (for 2D keys such as pixel x sample).
    static uint64_t combine(uint64_t a, uint64_t b) { return mix(a * 0x9e3779b97f4a7c15ULL + b); }

private:
    static uint64_t mix(uint64_t z) {  // splitmix64 finaliser
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    }

    uint64_t state_ = 0;
    uint64_t inc_ = 1;
};

}  // namespace vrl
