#include "util/system_memory.h"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <string>

namespace vrl::util {

uint64_t physicalMemoryBytes() {
    const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGESIZE);
    uint64_t bytes = pages > 0 && pageSize > 0 ? uint64_t(pages) * uint64_t(pageSize) : 0;
    // cgroup v2 ("max" when unlimited), then v1.
    for (const char* file : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
        std::ifstream in(file);
        std::string text;
        if (!(in >> text) || text.empty() || text.find_first_not_of("0123456789") != std::string::npos) continue;
        const uint64_t limit = std::stoull(text);
        if (limit > 0) bytes = bytes ? std::min(bytes, limit) : limit;
        break;
    }
    return bytes;
}

}  // namespace vrl::util
