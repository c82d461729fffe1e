// Scene bundles: a scene file and every file it references, shipped as one
// content-addressed blob (a serialised vrl.v1.SceneBundle named by its SHA-256).
// Validation is strict because bundles come from the network: an entry with an
// absolute path, a '..' component, an empty or odd name, a duplicate, or a link
// is refused, as is a bundle over the size or file-count limit.
#pragma once

#include "service/common/limits.h"
#include "vrl/v1/vrl.pb.h"

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace vrl::rpc {

// A refused bundle; the message names the entry and the rule.
struct BundleError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Builds the blob from files on disk: `files` (absolute or relative to the
// working directory) become entries relative to their deepest common
// directory; `scene` must be one of them. Throws BundleError for a file that
// is a symbolic link or cannot be read. `entries`, if given, receives the number of
// entries (a file listed twice is one entry): what the coordinator's file limit counts.
std::string makeBundleBlob(const std::filesystem::path& scene, const std::vector<std::filesystem::path>& files,
                           size_t* entries = nullptr);

// Parses and validates a blob; throws BundleError.
v1::SceneBundle parseBundleBlob(const std::string& blob, const ServiceLimits& limits);

// Writes a validated bundle's files under `directory` (created; must not
// exist) via a temporary sibling and a rename, so a crash leaves no half
// bundle. Returns the scene file's path.
std::filesystem::path extractBundle(const v1::SceneBundle& bundle, const std::filesystem::path& directory);

}  // namespace vrl::rpc
