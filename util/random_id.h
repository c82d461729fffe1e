// Random identifiers from the operating system's entropy (std::random_device):
// job ids, leases, tokens, names of temporary files and folders. Never used for
// rendering, whose random streams are keyed by (seed, pixel, sample).
#pragma once

#include <cstddef>
#include <string>

namespace vrl::util {

// `digits` random lowercase hex digits.
std::string randomHex(size_t digits);

}  // namespace vrl::util
