#include "util/atomic_file.h"

#include "util/random_id.h"

#include <cerrno>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace vrl::util {

std::filesystem::path temporarySibling(const std::filesystem::path& path) {
    return path.string() + "." + randomHex(8) + ".tmp";
}

void writeAtomically(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path& temporary)>& write) {
    const std::filesystem::path temporary = temporarySibling(path);
    try {
        write(temporary);
        std::filesystem::rename(temporary, path);
    } catch (...) {
        std::error_code ignored;
        std::filesystem::remove(temporary, ignored);
        throw;
    }
}

void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes) {
    writeAtomically(path, [&](const std::filesystem::path& temporary) {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out)
            throw std::runtime_error("cannot create '" + temporary.string() + "': " +
                                     std::generic_category().message(errno));
        out.write(bytes.data(), std::streamsize(bytes.size()));
        out.close();
        if (!out) throw std::runtime_error("cannot write '" + temporary.string() + "' (disk full?)");
    });
}

}  // namespace vrl::util
