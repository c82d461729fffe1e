#include "util/duration.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace vrl::util {

std::chrono::milliseconds parseDuration(const std::string& text) {
    const auto bad = [&] {
        return std::invalid_argument("'" + text + "' is not a duration: give a whole number and a unit, e.g. 7d, 12h, "
                                     "30m, 90s, 500ms (0: none)");
    };
    size_t digits = 0;
    while (digits < text.size() && text[digits] >= '0' && text[digits] <= '9') ++digits;
    if (digits == 0 || digits > 12) throw bad();
    const int64_t value = std::stoll(text.substr(0, digits));
    const std::string unit = text.substr(digits);
    int64_t scale = 0;
    if (unit == "ms") scale = 1;
    else if (unit == "s") scale = 1000;
    else if (unit == "m") scale = 60 * 1000;
    else if (unit == "h") scale = 3600 * 1000;
    else if (unit == "d") scale = 86400 * 1000;
    else if (unit.empty() && value == 0) scale = 1;
    else throw bad();
    if (value > std::numeric_limits<int64_t>::max() / scale) throw bad();
    return std::chrono::milliseconds(value * scale);
}

std::string formatDuration(std::chrono::milliseconds duration) {
    int64_t s = std::max<int64_t>(0, duration.count()) / 1000;
    const int64_t d = s / 86400, h = s / 3600 % 24, m = s / 60 % 60;
    s %= 60;
    if (d > 0) return std::to_string(d) + "d " + std::to_string(h) + "h";
    if (h > 0) return std::to_string(h) + "h " + std::to_string(m) + "m";
    if (m > 0) return std::to_string(m) + "m " + std::to_string(s) + "s";
    return std::to_string(s) + "s";
}

}  // namespace vrl::util
