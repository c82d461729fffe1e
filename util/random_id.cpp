#include "util/random_id.h"

#include <random>

namespace vrl::util {

std::string randomHex(size_t digits) {
    std::random_device device;
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    out.reserve(digits);
    for (size_t i = 0; i < digits; ++i) out += kHex[device() & 15];
    return out;
}

}  // namespace vrl::util
