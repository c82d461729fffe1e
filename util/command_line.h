// Command-line values that `vrl` and the benchmarks share: an image size "WxH"
// and scene defines "-D name=value". Each throws std::invalid_argument with the
// message `vrl render` prints (exit 2), naming the flag and what it got.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace vrl::util {

// "WxH": 1 to 9 decimal digits, a lower-case 'x', 1 to 9 decimal digits, nothing
// else (no sign, no spaces). Sizes are not range-checked here: "0x10" gives (0, 10).
std::pair<int, int> parseResolution(const std::string& text);

// parseResolution, then each side in 1..maxSide and W x H at most maxPixels;
// else "resolution WxH is outside the supported range (1..maxSide per side, at
// most maxPixels pixels)".
std::pair<int, int> parseResolution(const std::string& text, int maxSide, int64_t maxPixels);

// "-D name=value" entries into a map, the last of a repeated name winning; an
// entry without '=' or with an empty name is refused. The value may be empty
// and may hold '='.
std::map<std::string, std::string> parseDefines(const std::vector<std::string>& defines);

}  // namespace vrl::util
