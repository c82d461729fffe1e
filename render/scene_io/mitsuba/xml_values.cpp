#include "render/scene_io/mitsuba/xml_values.h"

#include "render/scene_io/mitsuba/spectrum.h"
#include "util/strings.h"

#include <Imath/ImathMatrix.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>

namespace vrl::xml {
namespace {

constexpr std::string_view kValueTags[] = {"float",    "integer", "boolean", "string",   "rgb",
                                           "spectrum", "point",   "vector",  "transform"};
// Mitsuba 0.5/0.6 value elements this parser does not implement.
constexpr std::string_view kUnsupportedValueTags[] = {"srgb", "blackbody", "animation"};

bool contains(std::span<const std::string_view> names, std::string_view name) {
    return std::find(names.begin(), names.end(), name) != names.end();
}

std::string_view trim(std::string_view text) {
    const auto isSpace = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
    while (!text.empty() && isSpace(text.front())) text.remove_prefix(1);
    while (!text.empty() && isSpace(text.back())) text.remove_suffix(1);
    return text;
}

// Tokens separated by commas and/or whitespace (Mitsuba's tokenize(str, ", ")).
std::vector<std::string_view> splitList(std::string_view text) {
    std::vector<std::string_view> tokens;
    size_t i = 0;
    const auto isSeparator = [](char c) { return c == ',' || std::isspace(static_cast<unsigned char>(c)) != 0; };
    while (i < text.size()) {
        while (i < text.size() && isSeparator(text[i])) ++i;
        const size_t start = i;
        while (i < text.size() && !isSeparator(text[i])) ++i;
        if (i > start) tokens.push_back(text.substr(start, i - start));
    }
    return tokens;
}

bool isIdentifierChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }

std::string inQuotes(std::string_view text) { return "'" + std::string(text) + "'"; }

// The element kinds that may carry a parameter of `type`.
std::vector<std::string_view> tagsFor(ParamType type) {
    switch (type) {
        case ParamType::Float: return {"float"};
        case ParamType::Integer: return {"integer"};
        case ParamType::Boolean: return {"boolean"};
        case ParamType::String: return {"string"};
        case ParamType::Color: return {"rgb", "spectrum", "float"};
        case ParamType::FloatOrName: return {"float", "string"};
        case ParamType::Point: return {"point", "vector"};
        case ParamType::Transform: return {"transform"};
    }
    return {};
}

std::string describeTags(const std::vector<std::string_view>& tags) {
    std::string out;
    for (size_t i = 0; i < tags.size(); ++i) {
        if (i > 0) out += i + 1 == tags.size() ? " or " : ", ";
        out += "<" + std::string(tags[i]) + ">";
    }
    return out;
}

Transform lookAtTransform(const Element& element) {
    element.checkAttributes({"origin", "target", "up"});
    const Vec3 origin = parseTriple(element, element.requireAttribute("origin"), "'origin'");
    const Vec3 target = parseTriple(element, element.requireAttribute("target"), "'target'");
    Vec3 up(0.0f);
    if (const auto text = element.attribute("up")) up = parseTriple(element, *text, "'up'");
    if (up.length2() == 0.0f && (target - origin).length2() > 0.0f) {
        // As Mitsuba: without 'up', any axis perpendicular to the view.
        up = Frame::fromNormal((target - origin).normalized()).s;
    }
    try {
        return Transform::lookAt(origin, target, up);
    } catch (const std::invalid_argument& e) {
        element.fail(e.what());
    }
}

Transform transformStep(const Element& step) {
    const std::string tag = step.tag();
    if (tag == "translate") {
        step.checkAttributes({"x", "y", "z", "value"});
        if (const auto value = step.attribute("value")) {
            if (step.has("x") || step.has("y") || step.has("z")) step.fail("give either 'value' or x, y, z, not both");
            return Transform::translate(parseTriple(step, *value, "'value'"));
        }
        return Transform::translate(parsePoint(step));
    }
    if (tag == "rotate") {
        step.checkAttributes({"x", "y", "z", "angle", "value"});
        const float angle = parseFloat(step, step.requireAttribute("angle"), "'angle'");
        Vec3 axis;
        if (const auto value = step.attribute("value")) {
            if (step.has("x") || step.has("y") || step.has("z")) step.fail("give either 'value' or x, y, z, not both");
            axis = parseTriple(step, *value, "'value'");
        } else {
            axis = parsePoint(step);
        }
        if (axis.length2() == 0.0f) step.fail("the rotation axis (x, y, z) is zero");
        return Transform::rotate(axis, angle);
    }
    if (tag == "scale") {
        step.checkAttributes({"x", "y", "z", "value"});
        const bool hasXyz = step.has("x") || step.has("y") || step.has("z");
        if (const auto value = step.attribute("value")) {
            if (hasXyz) step.fail("give either 'value' or x, y, z, not both");
            const auto tokens = splitList(*value);
            if (tokens.size() == 1) return Transform::scale(Vec3(parseFloat(step, tokens[0], "'value'")));
            return Transform::scale(parseTriple(step, *value, "'value'"));
        }
        if (!hasXyz) step.fail("missing 'value' or x, y, z");
        Vec3 factors(1.0f);
        if (const auto x = step.attribute("x")) factors.x = parseFloat(step, *x, "'x'");
        if (const auto y = step.attribute("y")) factors.y = parseFloat(step, *y, "'y'");
        if (const auto z = step.attribute("z")) factors.z = parseFloat(step, *z, "'z'");
        return Transform::scale(factors);
    }
    if (tag == "matrix") {
        step.checkAttributes({"value"});
        const std::string text = step.requireAttribute("value");
        const auto tokens = splitList(text);
        if (tokens.size() != 16)
            step.fail("a matrix needs 16 numbers (row-major), got " + std::to_string(tokens.size()));
        std::array<double, 16> rowMajor{};
        for (size_t i = 0; i < 16; ++i) rowMajor[i] = parseFloat(step, tokens[i], "matrix entry");
        if (rowMajor[12] != 0.0 || rowMajor[13] != 0.0 || rowMajor[14] != 0.0 || rowMajor[15] != 1.0)
            step.fail("the last matrix row must be \"0 0 0 1\" (only affine transforms are supported)");
        return Transform::fromRowMajor(rowMajor);
    }
    if (tag == "lookat" || tag == "lookAt") return lookAtTransform(step);
    step.fail("unknown element <" + tag + "> in <transform>; valid here: translate, rotate, scale, matrix, lookat");
}

}  // namespace

// ---------------------------------------------------------------- XmlFile

XmlFile::XmlFile(std::string text, std::string displayName, std::filesystem::path directory)
    : text_(std::move(text)), displayName_(std::move(displayName)), directory_(std::move(directory)) {
    for (size_t i = 0; i < text_.size(); ++i)
        if (text_[i] == '\n') newlines_.push_back(static_cast<std::ptrdiff_t>(i));
    const pugi::xml_parse_result result = document_.load_buffer(text_.data(), text_.size(), pugi::parse_default);
    if (!result) {
        throw SceneError({displayName_, lineAtOffset(result.offset), ""},
                         std::string("malformed XML: ") + result.description());
    }
    // The scene parser recurses into nested plugins (bsdfs, textures, integrators):
    // refuse absurd nesting here, iteratively, rather than overflow the stack later.
    std::vector<std::pair<pugi::xml_node, int>> stack{{document_.document_element(), 1}};
    while (!stack.empty()) {
        const auto [node, depth] = stack.back();
        stack.pop_back();
        if (depth > kMaxXmlDepth)
            throw SceneError({displayName_, lineOf(node), ""},
                             "elements nested deeper than " + std::to_string(kMaxXmlDepth) + " levels");
        for (const pugi::xml_node child : node.children())
            if (child.type() == pugi::node_element) stack.emplace_back(child, depth + 1);
    }
}

int XmlFile::lineAtOffset(std::ptrdiff_t offset) const {
    if (offset < 0) return 0;
    return static_cast<int>(std::lower_bound(newlines_.begin(), newlines_.end(), offset) - newlines_.begin()) + 1;
}

int XmlFile::lineOf(pugi::xml_node node) const { return lineAtOffset(node.offset_debug()); }

std::string readTextFile(const std::filesystem::path& path, const SourceLocation& where, const std::string& what,
                         std::uintmax_t maxBytes) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error))
        throw SceneError(where, "cannot find the " + what + " '" + path.string() + "'");
    const std::uintmax_t size = std::filesystem::file_size(path, error);
    if (!error && size > maxBytes)
        throw SceneError(where, "the " + what + " '" + path.string() + "' is " + std::to_string(size) +
                                    " bytes, over the limit of " + std::to_string(maxBytes) +
                                    " bytes for a scene file; split it or move geometry into mesh files");
    std::ifstream in(path, std::ios::binary);
    std::string text(std::istreambuf_iterator<char>(in), {});
    if (!in && !in.eof()) throw SceneError(where, "cannot read the " + what + " '" + path.string() + "'");
    return text;
}

// ---------------------------------------------------------------- substitution

Substitution substituteDefines(std::string_view text, const Defines& defines) {
    std::string out;
    size_t i = 0;
    while (i < text.size()) {
        if (text[i] != '$') {
            out += text[i++];
            continue;
        }
        size_t end = i + 1;
        while (end < text.size() && isIdentifierChar(text[end])) ++end;
        const std::string_view identifier = text.substr(i + 1, end - i - 1);
        const auto name = resolveParameter(identifier, defines);
        if (!name) return {std::nullopt, std::string(identifier)};
        out += defines.find(*name)->second;
        i += 1 + name->size();
    }
    return {out, ""};
}

std::optional<std::string> resolveParameter(std::string_view identifier, const Defines& defines) {
    for (size_t length = identifier.size(); length > 0; --length)
        if (defines.contains(identifier.substr(0, length))) return std::string(identifier.substr(0, length));
    return std::nullopt;
}

std::set<std::string> parameterReferences(const XmlFile& file) {
    std::set<std::string> names;
    std::vector<pugi::xml_node> stack{file.root()};
    while (!stack.empty()) {
        const pugi::xml_node node = stack.back();
        stack.pop_back();
        for (const pugi::xml_attribute a : node.attributes()) {
            const std::string_view value = a.value();
            for (size_t i = value.find('$'); i != std::string_view::npos; i = value.find('$', i + 1)) {
                size_t end = i + 1;
                while (end < value.size() && isIdentifierChar(value[end])) ++end;
                if (end > i + 1) names.emplace(value.substr(i + 1, end - i - 1));
            }
        }
        for (const pugi::xml_node child : node.children())
            if (child.type() == pugi::node_element) stack.push_back(child);
    }
    return names;
}

// ---------------------------------------------------------------- Element

SourceLocation Element::where() const {
    std::string description = "<" + tag();
    for (const char* attribute : {"type", "name", "id"}) {
        const pugi::xml_attribute a = node_.attribute(attribute);
        if (!a.empty()) description += std::string(" ") + attribute + "=\"" + a.value() + "\"";
    }
    description += ">";
    return {file_->displayName(), file_->lineOf(node_), description};
}

void Element::fail(const std::string& problem) const { throw SceneError(where(), problem); }

std::optional<std::string> Element::attribute(const char* name) const {
    const pugi::xml_attribute raw = node_.attribute(name);
    if (raw.empty()) return std::nullopt;
    Substitution value = substituteDefines(raw.value(), *defines_);
    if (!value.text) {
        const std::string& undefined = value.undefined;
        if (undefined.empty()) fail(std::string("attribute '") + name + "': '$' is not followed by a parameter name");
        fail(std::string("attribute '") + name + "' uses the undefined parameter $" + undefined +
             "; define it with <default name=\"" + undefined + "\" value=\"...\"/> or -D " + undefined + "=...");
    }
    return value.text;
}

std::string Element::requireAttribute(const char* name) const {
    auto value = attribute(name);
    if (!value) fail(std::string("missing required attribute '") + name + "'");
    return *value;
}

void Element::checkAttributes(std::initializer_list<std::string_view> allowed) const {
    for (const pugi::xml_attribute a : node_.attributes()) {
        if (std::find(allowed.begin(), allowed.end(), std::string_view(a.name())) == allowed.end()) {
            fail(std::string("unknown attribute '") + a.name() + "'; valid attributes: " +
                 (allowed.size() == 0 ? std::string("none") : joinNames(std::span(allowed.begin(), allowed.size()))));
        }
    }
}

std::vector<Element> Element::children() const {
    std::vector<Element> out;
    for (const pugi::xml_node child : node_.children()) {
        if (child.type() == pugi::node_element) {
            out.emplace_back(*file_, child, *defines_);
        } else if ((child.type() == pugi::node_pcdata || child.type() == pugi::node_cdata) &&
                   !trim(child.value()).empty()) {
            spdlog::warn("{}: ignoring unexpected text '{}'", where().describe(), trim(child.value()));
        }
    }
    return out;
}

std::filesystem::path Element::resolvePath(const std::string& filename) const {
    const std::filesystem::path path(filename);
    return (path.is_absolute() ? path : file_->directory() / path).lexically_normal();
}

// ---------------------------------------------------------------- values

bool isValueTag(std::string_view tag) { return contains(kValueTags, tag); }

std::string joinNames(std::span<const std::string_view> names) {
    std::string out;
    for (const std::string_view name : names) out += (out.empty() ? "" : ", ") + std::string(name);
    return out;
}

std::string joinNames(std::span<const std::string> names) {
    std::vector<std::string_view> views(names.begin(), names.end());
    return joinNames(std::span<const std::string_view>(views));
}

float parseFloat(const Element& element, std::string_view text, std::string_view what) {
    std::string_view number = trim(text);
    if (number.empty()) element.fail("missing number for " + std::string(what));
    if (number.front() == '+') number.remove_prefix(1);
    double value = 0.0;
    const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
    if (error == std::errc::result_out_of_range)
        element.fail(std::string(what) + " " + inQuotes(trim(text)) + " is out of range");
    if (error != std::errc() || end != number.data() + number.size())
        element.fail("cannot parse " + std::string(what) + " " + inQuotes(trim(text)) + " as a number");
    if (!std::isfinite(value)) element.fail(std::string(what) + " must be finite, got " + inQuotes(trim(text)));
    if (std::abs(value) > std::numeric_limits<float>::max())
        element.fail(std::string(what) + " " + inQuotes(trim(text)) + " is out of range");
    return static_cast<float>(value);
}

int parseInteger(const Element& element, std::string_view text, std::string_view what) {
    std::string_view number = trim(text);
    if (number.empty()) element.fail("missing integer for " + std::string(what));
    if (number.front() == '+') number.remove_prefix(1);
    long long value = 0;
    const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
    if (error != std::errc() || end != number.data() + number.size())
        element.fail("cannot parse " + std::string(what) + " " + inQuotes(trim(text)) + " as an integer");
    if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max())
        element.fail(std::string(what) + " " + inQuotes(trim(text)) + " is out of range");
    return static_cast<int>(value);
}

bool parseBoolean(const Element& element, std::string_view text, std::string_view what) {
    const std::string lower = util::toLower(trim(text));
    if (lower == "true") return true;
    if (lower == "false") return false;
    element.fail(std::string(what) + " must be 'true' or 'false', got " + inQuotes(text));
}

Vec3 parseTriple(const Element& element, std::string_view text, std::string_view what) {
    const auto tokens = splitList(text);
    if (tokens.size() != 3) element.fail(std::string(what) + " needs three numbers \"x, y, z\", got " + inQuotes(text));
    return {parseFloat(element, tokens[0], what), parseFloat(element, tokens[1], what),
            parseFloat(element, tokens[2], what)};
}

Rgb parseColor(const Element& element) {
    const std::string tag = element.tag();
    if (tag == "float") {
        element.checkAttributes({"name", "value"});
        return Rgb(parseFloat(element, element.requireAttribute("value"), "'value'"));
    }
    if (tag == "spectrum") {
        element.checkAttributes({"name", "value", "intent", "filename"});
        if (element.has("filename")) element.fail("spectra from files are not supported yet; give an <rgb> instead");
        const std::string text = element.requireAttribute("value");
        const auto tokens = splitList(text);
        if (text.find(':') != std::string::npos) {
            // Sampled spectrum "λ:v, ...", converted as Mitsuba's RGB build does (render/spectrum.h).
            if (element.has("intent"))
                element.fail("'intent' applies to a single uniform value only, not to wavelength:value pairs");
            try {
                return spectrumToRgb(parseWavelengthSpectrum(text));
            } catch (const std::invalid_argument& e) {
                element.fail(std::string("invalid sampled spectrum: ") + e.what());
            }
        }
        if (tokens.size() != 1)
            element.fail(
                "a <spectrum> must be a single uniform value here (discretised spectra are not supported yet), got " +
                inQuotes(text));
        return Rgb(parseFloat(element, tokens[0], "'value'"));
    }
    if (tag != "rgb") element.fail("expected <rgb>, <spectrum> or <float>, got <" + tag + ">");
    element.checkAttributes({"name", "value", "intent"});
    const std::string text = element.requireAttribute("value");
    const auto tokens = splitList(text);
    if (tokens.size() == 1 && tokens[0].size() == 7 && tokens[0][0] == '#') {
        unsigned encoded = 0;
        const auto [end, error] = std::from_chars(tokens[0].data() + 1, tokens[0].data() + 7, encoded, 16);
        if (error != std::errc() || end != tokens[0].data() + 7)
            element.fail("cannot parse the colour " + inQuotes(text));
        return {((encoded >> 16) & 0xFF) / 255.0f, ((encoded >> 8) & 0xFF) / 255.0f, (encoded & 0xFF) / 255.0f};
    }
    if (tokens.size() == 1) return Rgb(parseFloat(element, tokens[0], "'value'"));
    if (tokens.size() == 3)
        return {parseFloat(element, tokens[0], "'value'"), parseFloat(element, tokens[1], "'value'"),
                parseFloat(element, tokens[2], "'value'")};
    element.fail("an <rgb> needs one or three numbers (\"r, g, b\"), got " + inQuotes(text));
}

Vec3 parsePoint(const Element& element) {
    if (element.tag() == "point" || element.tag() == "vector")
        element.checkAttributes({"name", "x", "y", "z", "value"});
    if (const auto value = element.attribute("value")) {
        if (element.has("x") || element.has("y") || element.has("z"))
            element.fail("give either 'value' or x, y, z, not both");
        return parseTriple(element, *value, "'value'");
    }
    Vec3 p(0.0f);
    if (const auto x = element.attribute("x")) p.x = parseFloat(element, *x, "'x'");
    if (const auto y = element.attribute("y")) p.y = parseFloat(element, *y, "'y'");
    if (const auto z = element.attribute("z")) p.z = parseFloat(element, *z, "'z'");
    return p;
}

Transform parseTransform(const Element& element) {
    element.checkAttributes({"name"});
    Transform total;
    for (const Element& step : element.children()) total = total.then(transformStep(step));
    const std::array<double, 16> m = total.toRowMajor();
    const Imath::M33d linear(m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]);
    const double determinant = linear.determinant();
    if (determinant == 0.0 || !std::isfinite(determinant))
        element.fail("the transform is singular (a zero scale or a degenerate matrix)");
    return total;
}

// ---------------------------------------------------------------- PluginParams

PluginParams::PluginParams(const Element& plugin, std::string pluginName, std::span<const ParamSpec> specs,
                           std::initializer_list<std::string_view> objectTags)
    : plugin_(plugin), pluginName_(std::move(pluginName)) {
    std::vector<std::string_view> specNames;
    for (const ParamSpec& spec : specs) specNames.push_back(spec.name);

    for (const Element& child : plugin.children()) {
        const std::string tag = child.tag();
        if (contains(kValueTags, tag)) {
            const std::string name = child.requireAttribute("name");
            const auto spec =
                std::find_if(specs.begin(), specs.end(), [&](const ParamSpec& s) { return s.name == name; });
            if (spec == specs.end()) {
                child.fail("unknown parameter " + inQuotes(name) + " for " + pluginName_ + "; " +
                           (specs.empty()
                                ? std::string("it takes no parameters")
                                : "valid parameters: " + joinNames(std::span<const std::string_view>(specNames))));
            }
            const auto tags = tagsFor(spec->type);
            if (std::find(tags.begin(), tags.end(), tag) == tags.end())
                child.fail("parameter " + inQuotes(name) + " of " + pluginName_ + " must be given as " +
                           describeTags(tags) + ", not <" + tag + ">");
            if (const Param* previous = find(name))
                child.fail("parameter " + inQuotes(name) + " is given twice (first on line " +
                           std::to_string(previous->element.where().line) + ")");
            if (spec->use == ParamUse::Unsupported)
                child.fail("parameter " + inQuotes(name) + " of " + pluginName_ + " is not supported yet");
            params_.push_back({name, &*spec, child});
        } else if (std::find(objectTags.begin(), objectTags.end(), tag) != objectTags.end()) {
            objects_.push_back(child);
        } else if (contains(kUnsupportedValueTags, tag)) {
            child.fail("<" + tag + "> values are not supported yet");
        } else {
            std::vector<std::string_view> valid;
            for (const std::string_view valueTag : kValueTags) {
                const bool used = std::any_of(specs.begin(), specs.end(), [&](const ParamSpec& s) {
                    const auto tags = tagsFor(s.type);
                    return std::find(tags.begin(), tags.end(), valueTag) != tags.end();
                });
                if (used) valid.push_back(valueTag);
            }
            valid.insert(valid.end(), objectTags.begin(), objectTags.end());
            child.fail("unknown element <" + tag + "> in " + pluginName_ + "; " +
                       (valid.empty() ? std::string("it takes no nested elements")
                                      : "valid here: " + joinNames(std::span<const std::string_view>(valid))));
        }
    }
}

const PluginParams::Param* PluginParams::find(std::string_view name) const {
    const auto it = std::find_if(params_.begin(), params_.end(), [&](const Param& p) { return p.name == name; });
    return it == params_.end() ? nullptr : &*it;
}

const PluginParams::Param* PluginParams::findTyped(std::string_view name, ParamType type) const {
    const Param* param = find(name);
    if (param == nullptr || param->spec->use != ParamUse::Read) return nullptr;
    if (param->spec->type != type)  // a bug in a plugin's table, not in the scene
        throw std::logic_error("parameter '" + std::string(name) + "' read with the wrong type");
    return param;
}

std::optional<float> PluginParams::getFloat(std::string_view name) const {
    const Param* p = findTyped(name, ParamType::Float);
    if (!p) return std::nullopt;
    p->element.checkAttributes({"name", "value"});
    return parseFloat(p->element, p->element.requireAttribute("value"), inQuotes(name));
}

std::optional<int> PluginParams::getInteger(std::string_view name) const {
    const Param* p = findTyped(name, ParamType::Integer);
    if (!p) return std::nullopt;
    p->element.checkAttributes({"name", "value"});
    return parseInteger(p->element, p->element.requireAttribute("value"), inQuotes(name));
}

std::optional<bool> PluginParams::getBoolean(std::string_view name) const {
    const Param* p = findTyped(name, ParamType::Boolean);
    if (!p) return std::nullopt;
    p->element.checkAttributes({"name", "value"});
    return parseBoolean(p->element, p->element.requireAttribute("value"), inQuotes(name));
}

std::optional<std::string> PluginParams::getString(std::string_view name) const {
    const Param* p = findTyped(name, ParamType::String);
    if (!p) return std::nullopt;
    p->element.checkAttributes({"name", "value"});
    return p->element.requireAttribute("value");
}

std::optional<Rgb> PluginParams::getColor(std::string_view name) const {
    const Param* p = findTyped(name, ParamType::Color);
    if (!p) return std::nullopt;
    return parseColor(p->element);
}

std::optional<Vec3> PluginParams::getPoint(std::string_view name) const {
    const Param* p = findTyped(name, ParamType::Point);
    if (!p) return std::nullopt;
    return parsePoint(p->element);
}

std::optional<Transform> PluginParams::getTransform(std::string_view name) const {
    const Param* p = findTyped(name, ParamType::Transform);
    if (!p) return std::nullopt;
    return parseTransform(p->element);
}

std::optional<std::variant<float, std::string>> PluginParams::getFloatOrName(std::string_view name) const {
    const Param* p = findTyped(name, ParamType::FloatOrName);
    if (!p) return std::nullopt;
    p->element.checkAttributes({"name", "value"});
    const std::string value = p->element.requireAttribute("value");
    if (p->element.tag() == "string") return value;
    return parseFloat(p->element, value, inQuotes(name));
}

std::vector<std::string> PluginParams::ignoredParameters() const {
    std::vector<std::string> names;
    for (const Param& param : params_)
        if (param.spec->use == ParamUse::Ignore) names.push_back(param.name);
    return names;
}

const Element* PluginParams::element(std::string_view name) const {
    const Param* param = find(name);
    return param == nullptr ? nullptr : &param->element;
}

void PluginParams::fail(std::string_view name, const std::string& problem) const {
    const Param* param = find(name);
    if (param == nullptr) plugin_.fail(problem);
    param->element.fail(problem);
}

}  // namespace vrl::xml
