#include "service/job/scene_bundle.h"

#include "service/common/rpc_common.h"
#include "util/strings.h"

#include <fstream>
#include <set>
#include <sstream>
#include <system_error>
#include <thread>
#include <unistd.h>

namespace vrl::rpc {

namespace fs = std::filesystem;

std::string makeBundleBlob(const fs::path& scene, const std::vector<fs::path>& files, size_t* entries) {
    std::vector<fs::path> absolute;
    for (const auto& file : files) {
        std::error_code error;
        if (fs::is_symlink(file, error))
            throw BundleError("'" + file.string() + "' is a symbolic link; bundles hold only regular files (copy "
                              "the target into the scene folder)");
        absolute.push_back(fs::absolute(file).lexically_normal());
    }
    const fs::path sceneAbsolute = fs::absolute(scene).lexically_normal();
    // The deepest directory that holds every file.
    fs::path root = sceneAbsolute.parent_path();
    for (const auto& file : absolute) {
        while (true) {
            const auto relative = file.lexically_relative(root);
            if (!relative.empty() && *relative.begin() != "..") break;
            if (root == root.root_path()) break;
            root = root.parent_path();
        }
    }
    v1::SceneBundle bundle;
    bundle.set_scene_path(sceneAbsolute.lexically_relative(root).generic_string());
    std::set<std::string> seen;
    for (const auto& file : absolute) {
        const std::string relative = file.lexically_relative(root).generic_string();
        if (!seen.insert(relative).second) continue;  // referenced twice
        std::ifstream in(file, std::ios::binary);
        if (!in) throw BundleError("cannot read '" + file.string() + "' for the scene bundle");
        std::ostringstream data;
        data << in.rdbuf();
        auto* entry = bundle.add_entries();
        entry->set_path(relative);
        entry->set_data(data.str());
    }
    if (entries) *entries = size_t(bundle.entries_size());
    std::string blob;
    bundle.SerializeToString(&blob);
    return blob;
}

namespace {

void validatePath(const std::string& path) {
    if (path.empty()) throw BundleError("a bundle entry has an empty path");
    if (path.size() > 1024) throw BundleError("bundle entry path longer than 1024 characters");
    if (path.front() == '/' || path.find('\\') != std::string::npos || path.find(':') != std::string::npos)
        throw BundleError("bundle entry '" + path + "' has an absolute or non-portable path; entries are relative "
                          "paths with '/' separators");
    size_t start = 0;
    while (start <= path.size()) {
        const size_t end = std::min(path.find('/', start), path.size());
        const std::string part = path.substr(start, end - start);
        if (part.empty() || part == "." || part == "..")
            throw BundleError("bundle entry '" + path + "' has an empty, '.' or '..' component; entries must stay "
                              "inside the bundle");
        for (const char c : part)
            if (static_cast<unsigned char>(c) < 0x20) throw BundleError("bundle entry '" + path + "' has a control character");
        start = end + 1;
    }
}

}  // namespace

v1::SceneBundle parseBundleBlob(const std::string& blob, const ServiceLimits& limits) {
    if (blob.size() > limits.maxBundleBytes)
        throw BundleError("scene bundle of " + std::to_string(blob.size()) + " bytes exceeds the limit of " +
                          std::to_string(limits.maxBundleBytes) + " bytes");
    v1::SceneBundle bundle;
    if (!bundle.ParseFromString(blob)) throw BundleError("the scene bundle is not a valid vrl.v1.SceneBundle message");
    if (uint64_t(bundle.entries_size()) > limits.maxBundleFiles)
        throw BundleError("scene bundle has " + std::to_string(bundle.entries_size()) + " files; the limit is " +
                          std::to_string(limits.maxBundleFiles));
    std::set<std::string> paths;
    for (const auto& entry : bundle.entries()) {
        validatePath(entry.path());
        if (entry.kind() != v1::BundleEntry::KIND_FILE)
            throw BundleError("bundle entry '" + entry.path() + "' is a link; bundles hold only regular files");
        if (!paths.insert(entry.path()).second) throw BundleError("bundle entry '" + entry.path() + "' appears twice");
    }
    // A file "a" and a directory "a/..." cannot both exist.
    for (const auto& path : paths) {
        const auto next = paths.upper_bound(path + "/");
        if (next != paths.end() && next->rfind(path + "/", 0) == 0)
            throw BundleError("bundle entry '" + path + "' is both a file and a directory");
    }
    if (!paths.count(bundle.scene_path()))
        throw BundleError("the bundle's scene file '" + util::abbreviate(bundle.scene_path()) + "' is not among its entries");
    return bundle;
}

fs::path extractBundle(const v1::SceneBundle& bundle, const fs::path& directory) {
    fs::path staging = directory;
    staging += ".partial-" + std::to_string(::getpid()) + "-" +
               std::to_string(std::hash<std::thread::id>{}(std::this_thread::get_id()));
    std::error_code error;
    fs::remove_all(staging, error);
    fs::create_directories(staging);
    for (const auto& entry : bundle.entries()) {
        const fs::path target = staging / fs::path(entry.path());
        fs::create_directories(target.parent_path());
        std::ofstream out(target, std::ios::binary | std::ios::trunc);
        out.write(entry.data().data(), std::streamsize(entry.data().size()));
        if (!out) throw std::runtime_error("cannot write '" + target.string() + "' (disk full?)");
    }
    fs::rename(staging, directory, error);
    if (error) {
        fs::remove_all(staging, error);
        if (!fs::exists(directory)) throw std::runtime_error("cannot create '" + directory.string() + "'");
    }
    return directory / fs::path(bundle.scene_path());
}

}  // namespace vrl::rpc
