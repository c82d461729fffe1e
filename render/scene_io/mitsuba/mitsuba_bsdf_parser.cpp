#include "render/scene_io/mitsuba/mitsuba_bsdf_parser.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <variant>

#include "render/scene_io/mitsuba/ior_table.h"
#include "util/strings.h"

namespace vrl::mitsuba {
namespace {

using xml::Element;
using xml::ParamSpec;
using xml::PluginParams;
using T = xml::ParamType;
using U = xml::ParamUse;

// ---------------------------------------------------------------- plugin tables
// Parameters as in Mitsuba 0.5; defaults are those of BsdfDescription unless
// set in the parse function (plastic's intIOR, ward's specularReflectance).
// clang-format off
constexpr std::string_view kBsdfTypes[] = {
    "diffuse", "dielectric", "roughdielectric", "conductor", "roughconductor", "plastic", "roughplastic",
    "ward", "twosided", "bumpmap", "null"};
// Mitsuba 0.5 bsdfs with no counterpart here (named as such in the error).
constexpr std::string_view kUnsupportedBsdfTypes[] = {
    "thindielectric", "difftrans", "roughdiffuse", "coating", "roughcoating", "phong", "mixturebsdf",
    "blendbsdf", "mask", "hk", "irawan", "normalmap"};

constexpr ParamSpec kDiffuseParameters[] = {{"reflectance", T::Color}};
constexpr ParamSpec kDielectricParameters[] = {
    {"intIOR", T::FloatOrName}, {"extIOR", T::FloatOrName},
    {"specularReflectance", T::Color}, {"specularTransmittance", T::Color}};
constexpr ParamSpec kRoughDielectricParameters[] = {
    {"intIOR", T::FloatOrName}, {"extIOR", T::FloatOrName},
    {"specularReflectance", T::Color}, {"specularTransmittance", T::Color},
    {"distribution", T::String}, {"alpha", T::Float}, {"alphaU", T::Float}, {"alphaV", T::Float},
    {"sampleVisible", T::Boolean, U::Ignore}};
constexpr ParamSpec kConductorParameters[] = {
    {"material", T::String}, {"eta", T::Color}, {"k", T::Color}, {"extEta", T::FloatOrName},
    {"specularReflectance", T::Color}};
constexpr ParamSpec kRoughConductorParameters[] = {
    {"material", T::String}, {"eta", T::Color}, {"k", T::Color}, {"extEta", T::FloatOrName},
    {"specularReflectance", T::Color},
    {"distribution", T::String}, {"alpha", T::Float}, {"alphaU", T::Float}, {"alphaV", T::Float},
    {"sampleVisible", T::Boolean, U::Ignore}};
constexpr ParamSpec kPlasticParameters[] = {
    {"intIOR", T::FloatOrName}, {"extIOR", T::FloatOrName},
    {"diffuseReflectance", T::Color}, {"specularReflectance", T::Color}, {"nonlinear", T::Boolean}};
constexpr ParamSpec kRoughPlasticParameters[] = {
    {"intIOR", T::FloatOrName}, {"extIOR", T::FloatOrName},
    {"diffuseReflectance", T::Color}, {"specularReflectance", T::Color}, {"nonlinear", T::Boolean},
    {"distribution", T::String}, {"alpha", T::Float}, {"alphaU", T::Float}, {"alphaV", T::Float},
    {"sampleVisible", T::Boolean, U::Ignore}};
constexpr ParamSpec kWardParameters[] = {
    {"variant", T::String}, {"alpha", T::Float}, {"alphaU", T::Float}, {"alphaV", T::Float},
    {"diffuseReflectance", T::Color}, {"specularReflectance", T::Color}};

// The colour parameters that may also be given a texture.
constexpr std::string_view kDiffuseTextures[] = {"reflectance"};
constexpr std::string_view kDielectricTextures[] = {"specularReflectance", "specularTransmittance"};
constexpr std::string_view kConductorTextures[] = {"specularReflectance"};
constexpr std::string_view kPlasticTextures[] = {"diffuseReflectance", "specularReflectance"};  // also ward

// "as" is Mitsuba 0.5's alias of phong (its anisotropic form).
constexpr std::string_view kDistributions[] = {"beckmann", "ggx", "phong", "as"};
constexpr std::string_view kWardVariants[] = {"ward", "ward-duer", "balanced"};  // WardVariant order

constexpr std::string_view kTextureTypes[] = {"bitmap", "scale"};
constexpr ParamSpec kBitmapParameters[] = {
    {"filename", T::String}, {"wrapMode", T::String}, {"wrapModeU", T::String}, {"wrapModeV", T::String},
    {"gamma", T::Float}, {"uvscale", T::Float}, {"uscale", T::Float}, {"vscale", T::Float},
    {"uoffset", T::Float}, {"voffset", T::Float}, {"channel", T::String},
    {"filterType", T::String, U::Ignore}, {"maxAnisotropy", T::Float, U::Ignore}, {"cache", T::Boolean, U::Ignore}};
constexpr ParamSpec kScaleTextureParameters[] = {{"scale", T::Color}};
// TextureDescription::Wrap order, then Mitsuba's aliases black (= zero) and white (= one).
constexpr std::string_view kWrapModes[] = {"repeat", "mirror", "clamp", "zero", "one", "black", "white"};
constexpr std::string_view kFilterTypes[] = {"ewa", "trilinear", "nearest"};
// clang-format on

constexpr float kAirIor = 1.000277f;
constexpr float kPolypropyleneIor = 1.49f;

template <typename Range>
bool contains(const Range& names, std::string_view name) {
    return std::find(std::begin(names), std::end(names), name) != std::end(names);
}

// ---------------------------------------------------------------- parameters

// The textures given to a plugin's colour parameters (nested <texture> or
// <ref> to one), by parameter name.
class TextureArgs {
public:
    TextureArgs(ParseContext& context, const PluginParams& params, const std::string& plugin,
                std::span<const std::string_view> names) {
        const std::string valid = names.empty() ? std::string("none") : xml::joinNames(names);
        for (const Element& child : params.objects()) {
            const auto name = child.attribute("name");
            if (!name)
                child.fail("a <" + child.tag() + "> inside " + plugin +
                           " needs name=\"...\" naming the parameter it gives; texture parameters: " + valid);
            if (!contains(names, *name)) {
                if (*name == "alpha" || *name == "alphaU" || *name == "alphaV")
                    child.fail("a textured roughness ('" + *name + "') is not supported yet; give a <float>");
                child.fail("parameter '" + *name + "' of " + plugin +
                           " cannot be a texture; texture parameters: " + valid);
            }
            if (const Element* value = params.element(*name))
                child.fail("parameter '" + *name + "' is given twice (first on line " +
                           std::to_string(value->where().line) + ")");
            if (find(*name)) child.fail("parameter '" + *name + "' is given twice");
            TextureValue texture =
                child.tag() == "texture" ? parseTexture(context, child) : context.referencedTexture(child);
            args_.push_back({*name, std::move(texture), child.where()});
        }
    }

    struct Arg {
        std::string name;
        TextureValue texture;
        SourceLocation where;
    };
    const Arg* find(std::string_view name) const {
        const auto it = std::find_if(args_.begin(), args_.end(), [&](const Arg& a) { return a.name == name; });
        return it == args_.end() ? nullptr : &*it;
    }

private:
    std::vector<Arg> args_;
};

// A reflectance-like colour: a value or a texture. Negative values are an
// error; values above 1 are kept with a warning (not energy conserving).
ColorDescription reflectance(ParseContext& context, const PluginParams& params, const TextureArgs& textures,
                             const Element& plugin, std::string_view name, const Rgb& fallback) {
    if (const TextureArgs::Arg* arg = textures.find(name)) {
        if (maxComponent(arg->texture.scale) > 1.0f)
            spdlog::warn("{}: {} is a texture scaled by {}, which may exceed 1 (not energy conserving)",
                         arg->where.describe(), name, formatRgb(arg->texture.scale));
        return context.useTexture(arg->texture);
    }
    const Rgb value = nonNegativeColor(params, name, fallback);
    if (maxComponent(value) > 1.0f)
        spdlog::warn("{}: {} {} exceeds 1 (not energy conserving)", plugin.where().describe(), name, formatRgb(value));
    return ColorDescription{value, -1};
}

// An index of refraction: a positive number or one of Mitsuba's names.
float indexOfRefraction(const PluginParams& params, std::string_view name, float fallback, const std::string& plugin) {
    const auto given = params.getFloatOrName(name);
    if (!given) return fallback;
    float value = 0.0f;
    if (const auto* text = std::get_if<std::string>(&*given)) {
        const auto named = lookupDielectricIor(*text);
        if (!named) {
            std::vector<std::string_view> names;
            for (const NamedIor& ior : dielectricIors()) names.push_back(ior.name);
            params.fail(name, fmt::format("unknown index of refraction '{}' for '{}'; give a number or one of: {}",
                                          *text, name, xml::joinNames(names)));
        }
        value = *named;
    } else {
        value = std::get<float>(*given);
    }
    if (!(value > 0.0f)) params.fail(name, fmt::format("'{}' of {} must be positive, got {}", name, plugin, value));
    return value;
}

// intIOR and extIOR; rough interfaces (and plastics) need them to differ, as in Mitsuba.
void interfaceIors(const PluginParams& params, const Element& element, const std::string& plugin, float intDefault,
                   bool mustDiffer, BsdfDescription& bsdf) {
    bsdf.intIOR = indexOfRefraction(params, "intIOR", intDefault, plugin);
    bsdf.extIOR = indexOfRefraction(params, "extIOR", kAirIor, plugin);
    if (mustDiffer && bsdf.intIOR == bsdf.extIOR)
        element.fail(fmt::format("intIOR and extIOR of {} must differ (both are {})", plugin, bsdf.intIOR));
}

float positiveFloat(const PluginParams& params, std::string_view name, const std::string& plugin) {
    const float value = *params.getFloat(name);
    if (!(value > 0.0f)) params.fail(name, fmt::format("'{}' of {} must be positive, got {}", name, plugin, value));
    return value;
}

// distribution and alpha | alphaU + alphaV, with Mitsuba 0.5's rules.
void microfacet(const PluginParams& params, const std::string& plugin, bool isotropicOnly, BsdfDescription& bsdf) {
    if (const auto name = params.getString("distribution")) {
        const std::string lower = util::toLower(*name);
        if (lower == "beckmann") {
            bsdf.distribution = MicrofacetKind::Beckmann;
        } else if (lower == "ggx") {
            bsdf.distribution = MicrofacetKind::GGX;
        } else if (lower == "phong" || lower == "as") {
            bsdf.distribution = MicrofacetKind::Phong;
        } else {
            params.fail("distribution", "unknown distribution '" + *name + "' for " + plugin +
                                            "; valid distributions: " + xml::joinNames(kDistributions));
        }
    }
    const bool alpha = params.has("alpha"), alphaU = params.has("alphaU"), alphaV = params.has("alphaV");
    if (alpha && (alphaU || alphaV))
        params.fail(alphaU ? "alphaU" : "alphaV", "give either 'alpha' or 'alphaU' and 'alphaV', not both");
    if (alphaU != alphaV)
        params.fail(alphaU ? "alphaU" : "alphaV", "give both 'alphaU' and 'alphaV' (or a single 'alpha')");
    if (alpha) {
        bsdf.alphaU = bsdf.alphaV = positiveFloat(params, "alpha", plugin);
    } else if (alphaU) {
        bsdf.alphaU = positiveFloat(params, "alphaU", plugin);
        bsdf.alphaV = positiveFloat(params, "alphaV", plugin);
    }
    if (isotropicOnly && bsdf.alphaU != bsdf.alphaV)
        params.fail("alphaV", plugin + " supports only isotropic roughness: alphaU and alphaV must be equal");
}

void conductor(const PluginParams& params, const std::string& plugin, BsdfDescription& bsdf) {
    const std::string material = params.getString("material").value_or("Cu");
    const auto preset = lookupConductorPreset(material);
    if (!preset) {
        std::vector<std::string_view> names;
        for (const ConductorPreset& p : conductorPresets()) names.push_back(p.name);
        params.fail("material", "unknown conductor material '" + material +
                                    "'; valid materials: " + xml::joinNames(names) + " (or give 'eta' and 'k')");
    }
    // Stored as given (absolute); the model divides by extEta, as Mitsuba does.
    bsdf.eta = nonNegativeColor(params, "eta", preset->eta);
    bsdf.k = nonNegativeColor(params, "k", preset->k);
    bsdf.extEta = indexOfRefraction(params, "extEta", kAirIor, plugin);
}

// ---------------------------------------------------------------- nested plugins

BsdfDescription nestedBsdf(ParseContext& context, const Element& child) {
    return child.tag() == "bsdf" ? parseBsdf(context, child) : context.referencedBsdf(child);
}

BsdfDescription parseTwoSided(ParseContext& context, const Element& element, const std::string& plugin) {
    const PluginParams params(element, plugin, {}, {"bsdf", "ref"});
    const auto& nested = params.objects();
    if (nested.empty()) element.fail("twosided needs one nested <bsdf> or <ref>");
    if (nested.size() > 1) nested[1].fail("twosided with different front and back bsdfs is not supported yet");
    BsdfDescription bsdf = nestedBsdf(context, nested[0]);
    using Kind = BsdfDescription::Kind;
    if (bsdf.kind == Kind::Null || bsdf.kind == Kind::Dielectric || bsdf.kind == Kind::RoughDielectric)
        nested[0].fail(
            "twosided needs a reflecting bsdf such as diffuse, not null, dielectric or roughdielectric "
            "(as in Mitsuba, only materials without transmission can be nested)");
    bsdf.twoSided = true;
    return bsdf;
}

BsdfDescription parseBumpMap(ParseContext& context, const Element& element, const std::string& plugin) {
    const PluginParams params(element, plugin, {}, {"texture", "bsdf", "ref"});
    std::optional<BsdfDescription> bsdf;
    bool haveMap = false;
    for (const Element& child : params.objects()) {
        const bool isTexture = child.tag() == "texture" || (child.tag() == "ref" && context.lookup(child).texture);
        if (isTexture) {
            if (haveMap) child.fail("a bumpmap has only one texture (the displacement map)");
            // Checked (the file must exist) but not stored: nothing samples it.
            if (child.tag() == "texture") parseTexture(context, child);
            haveMap = true;
        } else {
            if (bsdf) child.fail("a bumpmap has only one nested bsdf");
            bsdf = nestedBsdf(context, child);
        }
    }
    if (!haveMap) element.fail("bumpmap needs a nested <texture> (the displacement map)");
    if (!bsdf) element.fail("bumpmap needs a nested <bsdf> or <ref> to one");
    const SourceLocation where = element.where();
    bsdf->approximations.push_back(
        fmt::format("bumpmap at {}:{}: bump map ignored, shading uses the unperturbed normal", where.file, where.line));
    return *bsdf;
}

}  // namespace

// ---------------------------------------------------------------- bsdf

BsdfDescription parseBsdf(ParseContext& context, const Element& element) {
    element.checkAttributes({"type", "id", "name"});
    const std::string written = util::toLower(element.requireAttribute("type"));
    if (contains(kUnsupportedBsdfTypes, written))
        element.fail("bsdf type '" + written +
                     "' (a Mitsuba plugin) is not supported; valid types: " + xml::joinNames(kBsdfTypes));
    const std::string type = pluginType(element, kBsdfTypes);
    const std::string plugin = pluginName(element, type);
    using Kind = BsdfDescription::Kind;
    BsdfDescription bsdf;

    if (type == "diffuse") {
        const PluginParams params(element, plugin, kDiffuseParameters, {"texture", "ref"});
        const TextureArgs textures(context, params, plugin, kDiffuseTextures);
        bsdf.kind = Kind::Diffuse;
        bsdf.reflectance = reflectance(context, params, textures, element, "reflectance", Rgb(0.5f));
    } else if (type == "dielectric" || type == "roughdielectric") {
        const bool rough = type == "roughdielectric";
        const PluginParams params(element, plugin,
                                  rough ? std::span<const ParamSpec>(kRoughDielectricParameters)
                                        : std::span<const ParamSpec>(kDielectricParameters),
                                  {"texture", "ref"});
        const TextureArgs textures(context, params, plugin, kDielectricTextures);
        bsdf.kind = rough ? Kind::RoughDielectric : Kind::Dielectric;
        interfaceIors(params, element, plugin, bsdf.intIOR, rough, bsdf);
        bsdf.specularReflectance = reflectance(context, params, textures, element, "specularReflectance", Rgb(1.0f));
        bsdf.specularTransmittance =
            reflectance(context, params, textures, element, "specularTransmittance", Rgb(1.0f));
        if (rough) microfacet(params, plugin, false, bsdf);
        context.reportIgnoredParameters(params, element, type, "no effect on the rendered image");
    } else if (type == "conductor" || type == "roughconductor") {
        const bool rough = type == "roughconductor";
        const PluginParams params(element, plugin,
                                  rough ? std::span<const ParamSpec>(kRoughConductorParameters)
                                        : std::span<const ParamSpec>(kConductorParameters),
                                  {"texture", "ref"});
        const TextureArgs textures(context, params, plugin, kConductorTextures);
        bsdf.kind = rough ? Kind::RoughConductor : Kind::Conductor;
        conductor(params, plugin, bsdf);
        bsdf.specularReflectance = reflectance(context, params, textures, element, "specularReflectance", Rgb(1.0f));
        if (rough) microfacet(params, plugin, false, bsdf);
        context.reportIgnoredParameters(params, element, type, "no effect on the rendered image");
    } else if (type == "plastic" || type == "roughplastic") {
        const bool rough = type == "roughplastic";
        const PluginParams params(element, plugin,
                                  rough ? std::span<const ParamSpec>(kRoughPlasticParameters)
                                        : std::span<const ParamSpec>(kPlasticParameters),
                                  {"texture", "ref"});
        const TextureArgs textures(context, params, plugin, kPlasticTextures);
        bsdf.kind = rough ? Kind::RoughPlastic : Kind::Plastic;
        interfaceIors(params, element, plugin, kPolypropyleneIor, rough, bsdf);
        bsdf.reflectance = reflectance(context, params, textures, element, "diffuseReflectance", Rgb(0.5f));
        bsdf.specularReflectance = reflectance(context, params, textures, element, "specularReflectance", Rgb(1.0f));
        bsdf.nonlinear = params.getBoolean("nonlinear").value_or(false);
        if (rough) microfacet(params, plugin, true, bsdf);
        context.reportIgnoredParameters(params, element, type, "no effect on the rendered image");
    } else if (type == "ward") {
        const PluginParams params(element, plugin, kWardParameters, {"texture", "ref"});
        const TextureArgs textures(context, params, plugin, kPlasticTextures);
        bsdf.kind = Kind::Ward;
        if (const auto variant = params.getString("variant")) {
            const std::string lower = util::toLower(*variant);
            const auto it = std::find(std::begin(kWardVariants), std::end(kWardVariants), lower);
            if (it == std::end(kWardVariants))
                params.fail("variant", "unknown ward variant '" + *variant +
                                           "'; valid variants: " + xml::joinNames(kWardVariants));
            bsdf.wardVariant = static_cast<BsdfDescription::WardVariant>(it - std::begin(kWardVariants));
        }
        // Mitsuba 0.5: alpha (default 0.1) sets both; alphaU/alphaV override it.
        if (params.has("alpha")) bsdf.alphaU = bsdf.alphaV = positiveFloat(params, "alpha", plugin);
        if (params.has("alphaU")) bsdf.alphaU = positiveFloat(params, "alphaU", plugin);
        if (params.has("alphaV")) bsdf.alphaV = positiveFloat(params, "alphaV", plugin);
        bsdf.reflectance = reflectance(context, params, textures, element, "diffuseReflectance", Rgb(0.5f));
        bsdf.specularReflectance = reflectance(context, params, textures, element, "specularReflectance", Rgb(0.2f));
    } else if (type == "twosided") {
        bsdf = parseTwoSided(context, element, plugin);
    } else if (type == "bumpmap") {
        bsdf = parseBumpMap(context, element, plugin);
    } else {  // null
        const PluginParams params(element, plugin, {}, {});
        bsdf.kind = Kind::Null;
    }
    context.registerId(element, NamedObject::ofBsdf(bsdf));
    return bsdf;
}

// ---------------------------------------------------------------- texture

namespace {

TextureDescription::Wrap wrapMode(const PluginParams& params, std::string_view name, TextureDescription::Wrap mode) {
    const auto text = params.getString(name);
    if (!text) return mode;
    const std::string lower = util::toLower(*text);
    const auto it = std::find(std::begin(kWrapModes), std::end(kWrapModes), lower);
    if (it == std::end(kWrapModes))
        params.fail(name, "unknown wrap mode '" + *text + "'; valid modes: " + xml::joinNames(kWrapModes));
    const auto index = it - std::begin(kWrapModes);
    if (lower == "black") return TextureDescription::Wrap::Zero;
    if (lower == "white") return TextureDescription::Wrap::One;
    return static_cast<TextureDescription::Wrap>(index);
}

TextureDescription parseBitmap(ParseContext& context, const Element& element, const std::string& plugin) {
    const PluginParams params(element, plugin, kBitmapParameters, {});
    TextureDescription bitmap;
    bitmap.where = element.where();
    bitmap.filename = context.requireFile(params, element, "filename", "texture file");
    const auto wrap = wrapMode(params, "wrapMode", TextureDescription::Wrap::Repeat);
    bitmap.wrapU = wrapMode(params, "wrapModeU", wrap);
    bitmap.wrapV = wrapMode(params, "wrapModeV", wrap);
    if (const auto gamma = params.getFloat("gamma")) {
        // Mitsuba: 0 = decide from the file (the default), -1 = sRGB, else a power law.
        if (*gamma != 0.0f && *gamma != -1.0f && !(*gamma > 0.0f))
            params.fail("gamma", fmt::format("gamma must be positive, -1 (sRGB) or 0 (automatic), got {}", *gamma));
        if (*gamma != 0.0f) bitmap.gamma = *gamma;
    }
    const float uvscale = params.getFloat("uvscale").value_or(1.0f);
    bitmap.uscale = params.getFloat("uscale").value_or(uvscale);
    bitmap.vscale = params.getFloat("vscale").value_or(uvscale);
    bitmap.uoffset = params.getFloat("uoffset").value_or(0.0f);
    bitmap.voffset = params.getFloat("voffset").value_or(0.0f);
    if (const auto channel = params.getString("channel"); channel && util::toLower(*channel) != "rgb")
        params.fail("channel", "channel '" + *channel + "' is not supported; only full-colour lookups ('rgb')");
    if (const Element* filter = params.element("filterType")) {
        const std::string text = filter->requireAttribute("value");
        if (!contains(kFilterTypes, util::toLower(text)))
            filter->fail("unknown filterType '" + text + "'; valid types: " + xml::joinNames(kFilterTypes));
    }
    context.reportIgnoredParameters(params, element, "bitmap",
                                    "lookups are bilinear on the full-resolution image (no mip-map filtering)");
    return bitmap;
}

TextureValue parseScaleTexture(ParseContext& context, const Element& element, const std::string& plugin) {
    const PluginParams params(element, plugin, kScaleTextureParameters, {"texture", "ref"});
    const auto& nested = params.objects();
    if (nested.empty()) element.fail("a scale texture needs a nested <texture> (or a <ref> to one)");
    if (nested.size() > 1) nested[1].fail("a scale texture has only one nested texture");
    TextureValue texture =
        nested[0].tag() == "texture" ? parseTexture(context, nested[0]) : context.referencedTexture(nested[0]);
    texture.scale *= nonNegativeColor(params, "scale", Rgb(1.0f));
    return texture;
}

}  // namespace

TextureValue parseTexture(ParseContext& context, const Element& element) {
    const std::string type = pluginType(element, kTextureTypes);
    const std::string plugin = pluginName(element, type);
    TextureValue texture;
    if (type == "bitmap")
        texture.bitmap = parseBitmap(context, element, plugin);
    else
        texture = parseScaleTexture(context, element, plugin);
    context.registerId(element, NamedObject::ofTexture(texture));
    return texture;
}

}  // namespace vrl::mitsuba
