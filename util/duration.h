// Durations as people type them on a command line: "7d", "12h", "30m", "90s",
// "250ms", or "0". Used by vrl-coordinator --retention and vrl jobs --purge
// --older-than; formatted back for listings ("3d 4h", "12m 5s").
#pragma once

#include <chrono>
#include <string>

namespace vrl::util {

// A non-negative whole number followed by a unit (ms, s, m, h, d; "0" needs none).
// Throws std::invalid_argument saying what is accepted.
std::chrono::milliseconds parseDuration(const std::string& text);

// The two largest units of a duration: "3d 4h", "2h 5m", "12m 5s", "7s", "0s".
std::string formatDuration(std::chrono::milliseconds duration);

}  // namespace vrl::util
