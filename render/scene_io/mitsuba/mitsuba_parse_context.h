// State shared by the parts of one Mitsuba 0.5/0.6 scene parse
// (mitsuba_parser.cpp: scene structure, sensor, shapes, emitters, media;
// mitsuba_bsdf_parser.cpp: bsdfs and textures). Internal to render/.
//  - the SceneDescription being built;
//  - the id table: as in Mitsuba, an id is global wherever its element is
//    nested (a bsdf inside a bumpmap, a medium inside a shape) and a <ref> may
//    name it anywhere after its declaration;
//  - the report of what is accepted without effect (SceneDescription::ignored):
//    one line per plugin kind, logged once however often the kind occurs;
//  - checks on referenced files (ParseOptions::confineTo, ::onFileReferenced).
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "render/description/scene_description.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "render/scene_io/mitsuba/xml_values.h"

namespace vrl::mitsuba {

// A texture as a colour parameter sees it: a bitmap times a constant factor
// (Mitsuba's `scale` texture). Stored in SceneDescription::textures only when
// a colour parameter uses it (ParseContext::useTexture).
struct TextureValue {
    TextureDescription bitmap;
    Rgb scale{1.0f};
};

// An object declared with an id.
struct NamedObject {
    std::string tag;  // element tag: "bsdf", "medium", "texture", "shape", ...
    std::optional<BsdfDescription> bsdf;
    std::optional<TextureValue> texture;
    int medium = -1;  // index into SceneDescription::media
    SourceLocation where;

    static NamedObject ofBsdf(BsdfDescription bsdf) {
        NamedObject object;
        object.bsdf = std::move(bsdf);
        return object;
    }
    static NamedObject ofTexture(TextureValue texture) {
        NamedObject object;
        object.texture = std::move(texture);
        return object;
    }
    static NamedObject ofMedium(int medium) {
        NamedObject object;
        object.medium = medium;
        return object;
    }
};

class ParseContext {
public:
    explicit ParseContext(const ParseOptions& options)
        : confineTo_(options.confineTo), onFileReferenced_(options.onFileReferenced) {}

    SceneDescription& scene() { return scene_; }

    // Records element's id (if it has one) with `object`; fails on a duplicate.
    void registerId(const xml::Element& element, NamedObject object);
    // The object a <ref id="..."> names; fails, listing the referable ids, if unknown.
    const NamedObject& lookup(const xml::Element& ref) const;
    // lookup() that also fails unless the object is a <bsdf> (a <texture>).
    BsdfDescription referencedBsdf(const xml::Element& ref) const;
    TextureValue referencedTexture(const xml::Element& ref) const;

    // Applies ParseOptions::confineTo and ::onFileReferenced to a referenced file.
    void checkReference(const xml::Element& element, const std::filesystem::path& path) const;
    // Parameter `name` (a <string> file name) resolved against the element's
    // file, checked by checkReference, and required to be an existing file;
    // `what` names it in errors ("OBJ file").
    std::filesystem::path requireFile(const xml::PluginParams& params, const xml::Element& element,
                                      std::string_view name, std::string_view what) const;

    // Records plugin `type` of element `plugin`'s kind (e.g. rfilter 'tent') as
    // accepted without effect for `reason`, with the parameters involved;
    // later calls for the same kind and type merge their parameters into one
    // line. `warn`: log at warning level (the image may differ from Mitsuba's),
    // else at info level. The line reads "rfilter 'tent' (parameters a, b): reason".
    void reportIgnored(const xml::Element& plugin, const std::string& type, const std::string& reason,
                       const std::vector<std::string>& parameters = {}, bool warn = false);
    // reportIgnored for the ParamUse::Ignore parameters `params` holds, if any.
    void reportIgnoredParameters(const xml::PluginParams& params, const xml::Element& plugin, const std::string& type,
                                 const std::string& reason);

    // The colour parameter for `texture`: its bitmap is stored in
    // SceneDescription::textures once per distinct description (the same file
    // with the same mapping is shared, even if the scene declares it twice).
    ColorDescription useTexture(const TextureValue& texture);
    // Records the approximations of a bsdf that a shape uses in
    // SceneDescription::approximations (each line once).
    void useBsdf(const BsdfDescription& bsdf);

    // Writes SceneDescription::ignored, logs each entry once, and hands the
    // description over. Call once, at the end of a successful parse.
    SceneDescription finish();

private:
    struct Ignored {
        std::string subject, reason;
        std::vector<std::string> parameters;
        SourceLocation where;  // first occurrence
        bool warn = false;
        std::unordered_set<std::string> seen;  // the names in `parameters`
    };

    std::optional<std::filesystem::path> confineTo_;
    std::function<void(const std::filesystem::path&)> onFileReferenced_;
    SceneDescription scene_;
    std::map<std::string, NamedObject, std::less<>> ids_;
    std::vector<Ignored> ignored_;
};

// ---- helpers shared by the parser's parts

std::string formatRgb(const Rgb& c);
// The plugin's `type` attribute, lower-cased as Mitsuba does; fails on a type
// not in `valid`, listing them (`extraHint` is appended to the message).
std::string pluginType(const xml::Element& element, std::span<const std::string_view> valid,
                       std::string_view extraHint = {});
// "bsdf type 'diffuse'" (for messages).
std::string pluginName(const xml::Element& element, const std::string& type);
// Colour parameter `name`, or `fallback`; fails on a negative component.
Rgb nonNegativeColor(const xml::PluginParams& params, std::string_view name, const Rgb& fallback);

}  // namespace vrl::mitsuba
