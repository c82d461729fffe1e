// Files that appear whole or not at all: the content goes to a temporary sibling
// (random name, so concurrent writers never share one) that is renamed over the
// destination; on any failure the temporary is removed and the destination is
// left as it was. Used for EXRs, previews, checkpoints, bundles and port files.
#pragma once

#include <filesystem>
#include <functional>
#include <string_view>

namespace vrl::util {

// A fresh temporary path beside `path` ("<path>.<8 hex>.tmp").
std::filesystem::path temporarySibling(const std::filesystem::path& path);

// Calls write(temporary), then renames the temporary to `path`. Exceptions from
// `write` or the rename propagate after the temporary is removed.
void writeAtomically(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path& temporary)>& write);

// writeAtomically with the bytes as the whole content; throws std::runtime_error
// naming the file when it cannot be written (disk full, no permission).
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace vrl::util
