// XML plumbing for the Mitsuba 0.5/0.6 scene parser (mitsuba_parser.cpp):
// loaded files that map node offsets back to 1-based lines, `$name`
// substitution in attribute values, parsing of value elements (numbers, rgb,
// spectrum, point/vector, transform) and the checked parameter list of one
// plugin element (`PluginParams`: a misspelled or wrongly typed parameter is an
// error that lists the valid names). Every error is a SceneError naming the
// file, line and element. Internal to render/: the public API is
// render/mitsuba_parser.h.
#pragma once

#include <filesystem>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <map>
#include <optional>
#include <pugixml.hpp>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "render/core/geometry.h"
#include "render/core/rgb.h"
#include "render/core/transform.h"
#include "render/description/scene_error.h"

namespace vrl::xml {

// Deepest element nesting a scene file may have (real scenes stay below 10);
// deeper files are refused with a SceneError naming the line.
inline constexpr int kMaxXmlDepth = 64;

// One parsed XML file. Keeps its text so that node offsets map to lines.
class XmlFile {
public:
    // `displayName` is used in messages; `directory` resolves relative paths
    // (includes, meshes). Throws SceneError with pugixml's message and the
    // line of the problem when the text is not well-formed XML.
    XmlFile(std::string text, std::string displayName, std::filesystem::path directory);
    XmlFile(const XmlFile&) = delete;
    XmlFile& operator=(const XmlFile&) = delete;

    pugi::xml_node root() const { return document_.document_element(); }
    int lineOf(pugi::xml_node node) const;  // 1-based; 0 if unknown
    int lineAtOffset(std::ptrdiff_t offset) const;
    const std::string& displayName() const { return displayName_; }
    const std::filesystem::path& directory() const { return directory_; }

private:
    std::string text_;
    std::string displayName_;
    std::filesystem::path directory_;
    std::vector<std::ptrdiff_t> newlines_;  // offsets of every '\n' in text_
    pugi::xml_document document_;
};

// The contents of `path`; a missing or unreadable file, or one larger than
// `maxBytes` (checked before reading), is a SceneError at `where` naming the
// path and `what` it was meant to be ("included file").
std::string readTextFile(const std::filesystem::path& path, const SourceLocation& where, const std::string& what,
                         std::uintmax_t maxBytes);

// `$name` definitions: -D overrides and <default> elements.
using Defines = std::map<std::string, std::string, std::less<>>;

// Replaces every `$name` in `text` by its definition. The longest defined name
// that prefixes the identifier after `$` wins (as in Mitsuba, where "$resx"
// prefers a parameter "resx" over "res"). Substituted text is not rescanned.
struct Substitution {
    std::optional<std::string> text;  // std::nullopt if a parameter is undefined
    std::string undefined;            // then the first undefined name ("" for a bare '$')
};
Substitution substituteDefines(std::string_view text, const Defines& defines);

// The name a `$identifier` reference resolves to under that rule (the longest
// defined prefix of `identifier`), or std::nullopt if none is defined.
std::optional<std::string> resolveParameter(std::string_view identifier, const Defines& defines);

// The identifiers after every '$' in `file`'s attribute values, read or not:
// what its `$name` references may use (for reporting -D defines a scene never uses).
std::set<std::string> parameterReferences(const XmlFile& file);

// An element of an XmlFile. Attribute values come back with `$name`
// substituted; errors name the file, line and element.
class Element {
public:
    Element(const XmlFile& file, pugi::xml_node node, const Defines& defines)
        : file_(&file), node_(node), defines_(&defines) {}

    std::string tag() const { return node_.name(); }
    const XmlFile& file() const { return *file_; }
    SourceLocation where() const;
    [[noreturn]] void fail(const std::string& problem) const;

    bool has(const char* attribute) const { return !node_.attribute(attribute).empty(); }
    std::optional<std::string> attribute(const char* name) const;
    std::string requireAttribute(const char* name) const;
    // Fails on any attribute not in `allowed`, listing the allowed ones.
    void checkAttributes(std::initializer_list<std::string_view> allowed) const;
    // Element children in document order (stray text is warned about).
    std::vector<Element> children() const;
    // `filename` made relative to the directory of this element's file (kept if absolute).
    std::filesystem::path resolvePath(const std::string& filename) const;

private:
    const XmlFile* file_;
    pugi::xml_node node_;
    const Defines* defines_;
};

// Whether `tag` is a value element (<float>, <rgb>, <transform>, ...).
bool isValueTag(std::string_view tag);

// "a, b, c" (for messages listing valid names).
std::string joinNames(std::span<const std::string_view> names);
std::string joinNames(std::span<const std::string> names);

// Numbers from attribute text; `what` names the value in messages. Floats must
// be finite and representable as float.
float parseFloat(const Element& element, std::string_view text, std::string_view what);
int parseInteger(const Element& element, std::string_view text, std::string_view what);
bool parseBoolean(const Element& element, std::string_view text, std::string_view what);
// "x, y, z" or "x y z" (exactly three numbers).
Vec3 parseTriple(const Element& element, std::string_view text, std::string_view what);

// <rgb value="r, g, b" | "v" | "#rrggbb">, <spectrum value="v"> (uniform) or
// <float value="v">, as linear RGB.
Rgb parseColor(const Element& element);
// <point>/<vector>: x, y, z attributes (missing ones are 0) or value="x, y, z".
Vec3 parsePoint(const Element& element);
// <transform>: translate, rotate, scale, matrix and lookat children, each
// applied after the previous ones. Fails on a singular result.
Transform parseTransform(const Element& element);

// How a plugin parameter is given in the XML.
enum class ParamType {
    Float,      // <float>
    Integer,    // <integer>
    Boolean,    // <boolean>
    String,     // <string>
    Color,      // <rgb>, <spectrum> or <float>
    FloatOrName,  // <float>, or <string> naming a value (e.g. the index of refraction "water")
    Point,      // <point> or <vector>
    Transform,  // <transform>
};
enum class ParamUse {
    Read,         // the plugin uses it
    Ignore,       // accepted, but has no effect here (see PluginParams::ignoredParameters)
    Unsupported,  // valid in Mitsuba, not implemented here (an error)
};
struct ParamSpec {
    std::string_view name;
    ParamType type;
    ParamUse use = ParamUse::Read;
};

// The children of one plugin element, e.g. <bsdf type="diffuse">: value
// children are parameters checked against `specs` (unknown name, wrong element
// kind, duplicate -> error listing the valid names); children whose tag is in
// `objectTags` (e.g. "bsdf", "ref") are kept as nested objects; any other
// child is an error listing the valid tags. Values are parsed when read.
class PluginParams {
public:
    PluginParams(const Element& plugin, std::string pluginName, std::span<const ParamSpec> specs,
                 std::initializer_list<std::string_view> objectTags);

    const std::vector<Element>& objects() const { return objects_; }
    bool has(std::string_view name) const { return find(name) != nullptr; }

    std::optional<float> getFloat(std::string_view name) const;
    std::optional<int> getInteger(std::string_view name) const;
    std::optional<bool> getBoolean(std::string_view name) const;
    std::optional<std::string> getString(std::string_view name) const;
    std::optional<Rgb> getColor(std::string_view name) const;
    std::optional<Vec3> getPoint(std::string_view name) const;
    std::optional<Transform> getTransform(std::string_view name) const;
    // A FloatOrName parameter: the number, or the name as written.
    std::optional<std::variant<float, std::string>> getFloatOrName(std::string_view name) const;
    // Names of the given parameters whose use is ParamUse::Ignore, in document
    // order; the caller reports them (PluginParams itself logs nothing).
    std::vector<std::string> ignoredParameters() const;

    // The element that gave parameter `name`, or nullptr.
    const Element* element(std::string_view name) const;
    // Throws a SceneError located at parameter `name` (at the plugin if absent).
    [[noreturn]] void fail(std::string_view name, const std::string& problem) const;

private:
    struct Param {
        std::string name;
        const ParamSpec* spec;
        Element element;
    };
    const Param* find(std::string_view name) const;
    const Param* findTyped(std::string_view name, ParamType type) const;

    Element plugin_;
    std::string pluginName_;
    std::vector<Param> params_;
    std::vector<Element> objects_;
};

}  // namespace vrl::xml
