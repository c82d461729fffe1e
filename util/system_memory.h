// The machine's memory, for refusing work that cannot fit before it starts.
#pragma once

#include <cstdint>

namespace vrl::util {

// Physical memory in bytes (sysconf), or the cgroup limit of this process when
// that is lower (a container); 0 if unknown.
uint64_t physicalMemoryBytes();

}  // namespace vrl::util
