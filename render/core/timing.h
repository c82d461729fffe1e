// Wall-clock timing for logs, statistics and benchmarks.
#pragma once

#include <chrono>

namespace vrl {

// Seconds elapsed on the steady clock since `start`.
inline double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace vrl
