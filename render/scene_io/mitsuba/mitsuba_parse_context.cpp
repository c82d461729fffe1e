#include "render/scene_io/mitsuba/mitsuba_parse_context.h"

#include "util/strings.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>

namespace vrl::mitsuba {
namespace {

// Object kinds a <ref> may name (listed when an id is unknown).
constexpr std::string_view kReferableTags[] = {"bsdf", "medium", "texture"};

bool sameTexture(const TextureDescription& a, const TextureDescription& b) {
    return a.filename == b.filename && a.uscale == b.uscale && a.vscale == b.vscale && a.uoffset == b.uoffset &&
           a.voffset == b.voffset && a.wrapU == b.wrapU && a.wrapV == b.wrapV && a.gamma == b.gamma;
}

}  // namespace

// ---------------------------------------------------------------- ids

void ParseContext::registerId(const xml::Element& element, NamedObject object) {
    const auto id = element.attribute("id");
    if (!id) return;
    if (id->empty()) element.fail("an id must not be empty");
    const auto previous = ids_.find(*id);
    if (previous != ids_.end())
        element.fail("duplicate id '" + *id + "' (first used at " + previous->second.where.describe() + ")");
    object.tag = element.tag();
    object.where = element.where();
    ids_.emplace(*id, std::move(object));
}

const NamedObject& ParseContext::lookup(const xml::Element& ref) const {
    ref.checkAttributes({"id", "name"});
    const std::string id = ref.requireAttribute("id");
    const auto it = ids_.find(id);
    if (it == ids_.end()) {
        std::vector<std::string> known;
        for (const auto& [name, named] : ids_)
            if (std::find(std::begin(kReferableTags), std::end(kReferableTags), named.tag) != std::end(kReferableTags))
                known.push_back(name + " (" + named.tag + ")");
        ref.fail("unknown id '" + id + "'; " +
                 (known.empty() ? std::string("no bsdf, medium or texture ids are declared before this point")
                                : "known ids: " + xml::joinNames(std::span<const std::string>(known))));
    }
    return it->second;
}

BsdfDescription ParseContext::referencedBsdf(const xml::Element& ref) const {
    const NamedObject& named = lookup(ref);
    if (!named.bsdf)
        ref.fail("id '" + ref.requireAttribute("id") + "' names a <" + named.tag + "> (" + named.where.describe() +
                 "), not a <bsdf>");
    return *named.bsdf;
}

TextureValue ParseContext::referencedTexture(const xml::Element& ref) const {
    const NamedObject& named = lookup(ref);
    if (!named.texture)
        ref.fail("id '" + ref.requireAttribute("id") + "' names a <" + named.tag + "> (" + named.where.describe() +
                 "), not a <texture>");
    return *named.texture;
}

// ---------------------------------------------------------------- files

void ParseContext::checkReference(const xml::Element& element, const std::filesystem::path& path) const {
    if (confineTo_) {
        std::error_code error;
        const auto root = std::filesystem::weakly_canonical(*confineTo_, error);
        const auto target = std::filesystem::weakly_canonical(path, error);
        const auto relative = target.lexically_relative(root);
        if (error || relative.empty() || *relative.begin() == ".." || relative.is_absolute())
            element.fail("'" + path.string() +
                         "' lies outside the scene bundle; a bundled scene may only reference "
                         "files inside it");
    }
    if (onFileReferenced_) onFileReferenced_(path);
}

std::filesystem::path ParseContext::requireFile(const xml::PluginParams& params, const xml::Element& element,
                                                std::string_view name, std::string_view what) const {
    const auto filename = params.getString(name);
    if (!filename) element.fail(fmt::format("missing parameter '{}' (the {})", name, what));
    const std::filesystem::path path = element.resolvePath(*filename);
    checkReference(*params.element(name), path);
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error))
        params.fail(name, fmt::format("cannot find the {} '{}'", what, path.string()));
    return path;
}

// ---------------------------------------------------------------- reports

void ParseContext::reportIgnored(const xml::Element& plugin, const std::string& type, const std::string& reason,
                                 const std::vector<std::string>& parameters, bool warn) {
    const std::string subject = plugin.tag() + " '" + type + "'";
    auto it = std::find_if(ignored_.begin(), ignored_.end(), [&](const Ignored& i) { return i.subject == subject; });
    if (it == ignored_.end()) {
        ignored_.push_back({subject, reason, {}, plugin.where(), warn, {}});
        it = std::prev(ignored_.end());
    }
    it->warn = it->warn || warn;
    // A set beside the list keeps this linear in the parameters a hostile file can repeat.
    for (const std::string& parameter : parameters)
        if (it->seen.insert(parameter).second) it->parameters.push_back(parameter);
}

void ParseContext::reportIgnoredParameters(const xml::PluginParams& params, const xml::Element& plugin,
                                           const std::string& type, const std::string& reason) {
    const std::vector<std::string> names = params.ignoredParameters();
    if (!names.empty()) reportIgnored(plugin, type, reason, names);
}

ColorDescription ParseContext::useTexture(const TextureValue& texture) {
    auto& textures = scene_.textures;
    const auto same = std::find_if(textures.begin(), textures.end(),
                                   [&](const TextureDescription& t) { return sameTexture(t, texture.bitmap); });
    const int index = static_cast<int>(same - textures.begin());
    if (same == textures.end()) textures.push_back(texture.bitmap);
    return ColorDescription{texture.scale, index};
}

void ParseContext::useBsdf(const BsdfDescription& bsdf) {
    auto& notes = scene_.approximations;
    for (const std::string& note : bsdf.approximations)
        if (std::find(notes.begin(), notes.end(), note) == notes.end()) notes.push_back(note);
}

SceneDescription ParseContext::finish() {
    for (const Ignored& entry : ignored_) {
        std::string line = entry.subject;
        if (!entry.parameters.empty())
            line += " (parameters " + xml::joinNames(std::span<const std::string>(entry.parameters)) + ")";
        line += ": " + entry.reason;
        spdlog::log(entry.warn ? spdlog::level::warn : spdlog::level::info, "{}: accepted without effect: {}",
                    entry.where.describe(), line);
        scene_.ignored.push_back(std::move(line));
    }
    ignored_.clear();
    return std::move(scene_);
}

// ---------------------------------------------------------------- helpers

std::string formatRgb(const Rgb& c) { return fmt::format("({}, {}, {})", c.x, c.y, c.z); }

std::string pluginType(const xml::Element& element, std::span<const std::string_view> valid,
                       std::string_view extraHint) {
    element.checkAttributes({"type", "id", "name"});
    const std::string type = util::toLower(element.requireAttribute("type"));
    if (std::find(valid.begin(), valid.end(), type) == valid.end())
        element.fail("unknown " + element.tag() + " type '" + type + "'; valid types: " + xml::joinNames(valid) +
                     std::string(extraHint));
    return type;
}

std::string pluginName(const xml::Element& element, const std::string& type) {
    return element.tag() + " type '" + type + "'";
}

Rgb nonNegativeColor(const xml::PluginParams& params, std::string_view name, const Rgb& fallback) {
    const auto color = params.getColor(name);
    if (!color) return fallback;
    if (minComponent(*color) < 0.0f)
        params.fail(name, "'" + std::string(name) + "' must be non-negative, got " + formatRgb(*color));
    return *color;
}

}  // namespace vrl::mitsuba
