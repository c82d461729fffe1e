#include "util/command_line.h"

#include <stdexcept>

namespace vrl::util {

namespace {

// A run of 1 to 9 ASCII digits as an int (9 digits cannot overflow it); -1 if `text` is not one.
int smallNumber(const std::string& text) {
    if (text.empty() || text.size() > 9) return -1;
    int value = 0;
    for (const char c : text) {
        if (c < '0' || c > '9') return -1;
        value = value * 10 + (c - '0');
    }
    return value;
}

}  // namespace

std::pair<int, int> parseResolution(const std::string& text) {
    const size_t x = text.find('x');
    const int width = x == std::string::npos ? -1 : smallNumber(text.substr(0, x));
    const int height = x == std::string::npos ? -1 : smallNumber(text.substr(x + 1));
    if (width < 0 || height < 0)
        throw std::invalid_argument("--resolution expects WxH (e.g. 640x480), got '" + text + "'");
    return {width, height};
}

std::pair<int, int> parseResolution(const std::string& text, int maxSide, int64_t maxPixels) {
    const auto [width, height] = parseResolution(text);
    if (width < 1 || height < 1 || width > maxSide || height > maxSide || int64_t(width) * height > maxPixels)
        throw std::invalid_argument("resolution " + text + " is outside the supported range (1.." +
                                    std::to_string(maxSide) + " per side, at most " + std::to_string(maxPixels) +
                                    " pixels)");
    return {width, height};
}

std::map<std::string, std::string> parseDefines(const std::vector<std::string>& defines) {
    std::map<std::string, std::string> out;
    for (const auto& d : defines) {
        const auto eq = d.find('=');
        if (eq == std::string::npos || eq == 0) throw std::invalid_argument("-D expects name=value, got '" + d + "'");
        out[d.substr(0, eq)] = d.substr(eq + 1);
    }
    return out;
}

}  // namespace vrl::util
