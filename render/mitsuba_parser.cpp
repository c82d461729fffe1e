#include "render/mitsuba_parser.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <numbers>

#include "render/xml_values.h"

namespace vrl {
namespace {

using xml::Element;
using xml::ParamSpec;
using xml::PluginParams;

// ---------------------------------------------------------------- plugin tables
// Each plugin's parameters and how they are used; extend a table to accept more.
using T = xml::ParamType;
using U = xml::ParamUse;
// clang-format off
constexpr std::string_view kIntegratorTypes[] = {
    "volpath", "volpath_simple", "path", "direct", "vrl", "vrlcuts", "vpl"};
constexpr ParamSpec kIntegratorParameters[] = {
    {"maxDepth", T::Integer}, {"rrDepth", T::Integer, U::Ignore},
    {"strictNormals", T::Boolean, U::Ignore}, {"hideEmitters", T::Boolean, U::Ignore},
    {"version", T::Integer, U::Ignore}};  // lajolla's integrator version tag

constexpr std::string_view kSensorTypes[] = {"perspective"};
constexpr ParamSpec kPerspectiveParameters[] = {
    {"fov", T::Float}, {"fovAxis", T::String}, {"focalLength", T::String}, {"toWorld", T::Transform},
    {"nearClip", T::Float}, {"farClip", T::Float}, {"focusDistance", T::Float, U::Ignore},
    {"shutterOpen", T::Float, U::Ignore}, {"shutterClose", T::Float, U::Ignore}};

constexpr std::string_view kFilmTypes[] = {"hdrfilm", "ldrfilm"};
constexpr ParamSpec kFilmParameters[] = {
    {"width", T::Integer}, {"height", T::Integer},
    {"fileFormat", T::String, U::Ignore}, {"pixelFormat", T::String, U::Ignore},
    {"componentFormat", T::String, U::Ignore}, {"banner", T::Boolean, U::Ignore},
    {"highQualityEdges", T::Boolean, U::Ignore}, {"attachLog", T::Boolean, U::Ignore},
    {"gamma", T::Float, U::Ignore}, {"exposure", T::Float, U::Ignore}, {"tonemapMethod", T::String, U::Ignore},
    {"key", T::Float, U::Ignore}, {"burn", T::Float, U::Ignore},
    {"cropOffsetX", T::Integer, U::Unsupported}, {"cropOffsetY", T::Integer, U::Unsupported},
    {"cropWidth", T::Integer, U::Unsupported}, {"cropHeight", T::Integer, U::Unsupported}};

// All treated as independent sampling with `sampleCount` samples per pixel.
constexpr std::string_view kSamplerTypes[] = {"independent", "ldsampler", "stratified", "halton", "sobol"};
constexpr ParamSpec kSamplerParameters[] = {
    {"sampleCount", T::Integer}, {"scramble", T::Integer, U::Ignore}, {"dimension", T::Integer, U::Ignore}};

constexpr std::string_view kBsdfTypes[] = {"diffuse", "null", "twosided"};
constexpr ParamSpec kDiffuseParameters[] = {{"reflectance", T::Color}};

// In ShapeDescription::Kind order.
constexpr std::string_view kShapeTypes[] = {"obj", "rectangle", "cube", "sphere", "disk"};
constexpr ParamSpec kBasicShapeParameters[] = {{"toWorld", T::Transform}, {"flipNormals", T::Boolean}};
constexpr ParamSpec kSphereParameters[] = {
    {"toWorld", T::Transform}, {"flipNormals", T::Boolean}, {"center", T::Point}, {"radius", T::Float}};
constexpr ParamSpec kObjParameters[] = {
    {"filename", T::String}, {"toWorld", T::Transform}, {"flipNormals", T::Boolean}, {"faceNormals", T::Boolean},
    {"flipTexCoords", T::Boolean, U::Ignore}, {"maxSmoothAngle", T::Float, U::Unsupported}};

constexpr std::string_view kShapeEmitterTypes[] = {"area"};
constexpr ParamSpec kAreaParameters[] = {{"radiance", T::Color}, {"samplingWeight", T::Float, U::Ignore}};
constexpr std::string_view kSceneEmitterTypes[] = {"point", "spot"};
constexpr ParamSpec kPointParameters[] = {
    {"intensity", T::Color}, {"position", T::Point}, {"toWorld", T::Transform},
    {"samplingWeight", T::Float, U::Ignore}};
constexpr ParamSpec kSpotParameters[] = {
    {"intensity", T::Color}, {"cutoffAngle", T::Float}, {"beamWidth", T::Float}, {"toWorld", T::Transform},
    {"samplingWeight", T::Float, U::Ignore}};

constexpr std::string_view kMediumTypes[] = {"homogeneous"};
constexpr ParamSpec kHomogeneousParameters[] = {
    {"sigmaS", T::Color}, {"sigmaA", T::Color}, {"sigmaT", T::Color}, {"albedo", T::Color}, {"scale", T::Float},
    {"material", T::String, U::Unsupported}};

constexpr std::string_view kPhaseTypes[] = {"isotropic", "hg"};
constexpr ParamSpec kHgParameters[] = {{"g", T::Float}};

constexpr std::string_view kSceneChildren[] = {
    "default", "include", "integrator", "sensor", "shape", "bsdf", "medium", "emitter"};
constexpr std::string_view kFovAxes[] = {"x", "y", "diagonal", "smaller", "larger"};  // FovAxis order
// clang-format on

constexpr int kMaxIncludeDepth = 64;

// ---------------------------------------------------------------- helpers

std::string lowercase(std::string text) {
    std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
    return text;
}

std::string formatRgb(const Rgb& c) { return fmt::format("({}, {}, {})", c.x, c.y, c.z); }

// The plugin's `type` attribute, lower-cased as Mitsuba does; fails on a type not in `valid`.
std::string pluginType(const Element& element, std::span<const std::string_view> valid,
                       std::string_view extraHint = {}) {
    element.checkAttributes({"type", "id", "name"});
    const std::string type = lowercase(element.requireAttribute("type"));
    if (std::find(valid.begin(), valid.end(), type) == valid.end())
        element.fail("unknown " + element.tag() + " type '" + type + "'; valid types: " + xml::joinNames(valid) +
                     std::string(extraHint));
    return type;
}

std::string pluginName(const Element& element, const std::string& type) {
    return element.tag() + " type '" + type + "'";
}

Rgb nonNegativeColor(const PluginParams& params, std::string_view name, const Rgb& fallback) {
    const auto color = params.getColor(name);
    if (!color) return fallback;
    if (minComponent(*color) < 0.0f)
        params.fail(name, "'" + std::string(name) + "' must be non-negative, got " + formatRgb(*color));
    return *color;
}

// ---------------------------------------------------------------- the parser

class SceneParser {
public:
    explicit SceneParser(const ParseOptions& options)
        : defines_(options.defines.begin(), options.defines.end()),
          confineTo_(options.confineTo),
          onFileReferenced_(options.onFileReferenced) {}

    SceneDescription parse(std::unique_ptr<xml::XmlFile> file, const std::filesystem::path& identity,
                           std::optional<std::filesystem::path> canonicalPath);

private:
    // An object declared with an id (bsdf and medium can be referenced).
    struct Named {
        std::string tag;
        std::optional<BsdfDescription> bsdf;
        int medium = -1;
        SourceLocation where;
    };

    void parseSceneChildren(const Element& scene);
    void parseDefault(const Element& element);
    void parseInclude(const Element& element);
    void parseIntegrator(const Element& element);
    void parseSensor(const Element& element);
    void parseFilm(const Element& element, SensorDescription& sensor);
    void parseSampler(const Element& element, SensorDescription& sensor);
    BsdfDescription parseBsdf(const Element& element);
    int parseMedium(const Element& element);
    PhaseDescription parsePhase(const Element& element);
    void parseShape(const Element& element);
    Rgb parseAreaEmitter(const Element& element);
    EmitterDescription parseEmitter(const Element& element);

    // Records element's id (if any) for <ref> and duplicate checks.
    void registerId(const Element& element, std::optional<BsdfDescription> bsdf = {}, int medium = -1);
    const Named& lookup(const Element& ref);
    BsdfDescription referencedBsdf(const Element& ref);
    int referencedMedium(const Element& ref);
    int mediumChild(const Element& child, int current);  // nested <medium> or <ref> to one

    // Applies ParseOptions::confineTo and ::onFileReferenced to a referenced file.
    void checkReference(const Element& element, const std::filesystem::path& path) const;

    xml::Defines defines_;
    std::optional<std::filesystem::path> confineTo_;
    std::function<void(const std::filesystem::path&)> onFileReferenced_;
    std::vector<std::unique_ptr<xml::XmlFile>> files_;  // alive while their elements are in use
    std::vector<std::filesystem::path> includeStack_;   // canonical paths, for cycle detection
    std::map<std::string, Named> ids_;
    SceneDescription scene_;
    std::optional<SourceLocation> sensorAt_, integratorAt_;
};

SceneDescription SceneParser::parse(std::unique_ptr<xml::XmlFile> file, const std::filesystem::path& identity,
                                    std::optional<std::filesystem::path> canonicalPath) {
    const Element root(*file, file->root(), defines_);
    files_.push_back(std::move(file));
    if (root.tag() != "scene") root.fail("the root element must be <scene>, not <" + root.tag() + ">");
    root.checkAttributes({"version"});
    scene_.version = root.requireAttribute("version");
    const std::string& version = scene_.version;
    const bool wellFormed = !version.empty() && std::isdigit(static_cast<unsigned char>(version[0])) &&
                            std::all_of(version.begin(), version.end(),
                                        [](char c) { return std::isdigit(static_cast<unsigned char>(c)) || c == '.'; });
    if (!wellFormed) root.fail("malformed scene version '" + version + "' (expected e.g. \"0.5.0\")");
    if (version.rfind("0.", 0) != 0)
        root.fail("scene version " + version + " is not Mitsuba 0.x syntax; this parser reads Mitsuba 0.5/0.6 scenes");
    scene_.file = identity;
    if (canonicalPath) includeStack_.push_back(*canonicalPath);

    parseSceneChildren(root);

    if (!sensorAt_) spdlog::warn("{}: the scene has no <sensor>; using the default camera", identity.string());
    if (!integratorAt_)
        spdlog::debug("{}: the scene has no <integrator>; using {}", identity.string(), scene_.integrator.type);
    return std::move(scene_);
}

void SceneParser::parseSceneChildren(const Element& scene) {
    for (const Element& child : scene.children()) {
        const std::string tag = child.tag();
        if (tag == "default") {
            parseDefault(child);
        } else if (tag == "include") {
            parseInclude(child);
        } else if (tag == "integrator") {
            parseIntegrator(child);
        } else if (tag == "sensor") {
            parseSensor(child);
        } else if (tag == "shape") {
            parseShape(child);
        } else if (tag == "bsdf") {
            parseBsdf(child);
            if (!child.has("id"))
                spdlog::warn("{}: a top-level <bsdf> without an id is never used", child.where().describe());
        } else if (tag == "medium") {
            parseMedium(child);
            if (!child.has("id"))
                spdlog::warn("{}: a top-level <medium> without an id is never used", child.where().describe());
        } else if (tag == "emitter") {
            if (lowercase(child.attribute("type").value_or("")) == "area")
                child.fail("attach area emitters to a shape (put the <emitter type=\"area\"> inside a <shape>)");
            scene_.emitters.push_back(parseEmitter(child));
        } else if (tag == "texture") {
            child.fail("<texture> is not supported yet");
        } else {
            child.fail("unknown element <" + tag + "> in <scene>; valid here: " + xml::joinNames(kSceneChildren));
        }
    }
}

void SceneParser::checkReference(const Element& element, const std::filesystem::path& path) const {
    if (confineTo_) {
        std::error_code error;
        const auto root = std::filesystem::weakly_canonical(*confineTo_, error);
        const auto target = std::filesystem::weakly_canonical(path, error);
        const auto relative = target.lexically_relative(root);
        if (error || relative.empty() || *relative.begin() == ".." || relative.is_absolute())
            element.fail("'" + path.string() + "' lies outside the scene bundle; a bundled scene may only reference "
                         "files inside it");
    }
    if (onFileReferenced_) onFileReferenced_(path);
}

void SceneParser::parseDefault(const Element& element) {
    element.checkAttributes({"name", "value"});
    const std::string name = element.requireAttribute("name");
    const bool identifier = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    });
    if (!identifier) element.fail("invalid parameter name '" + name + "' (use letters, digits and '_')");
    const std::string value = element.requireAttribute("value");
    defines_.try_emplace(name, value);  // a -D define or an earlier <default> wins
}

void SceneParser::parseInclude(const Element& element) {
    element.checkAttributes({"filename"});
    const std::filesystem::path path = element.resolvePath(element.requireAttribute("filename"));
    checkReference(element, path);
    const std::string text = xml::readTextFile(path, element.where(), "included file");
    std::error_code error;
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, error);
    if (std::find(includeStack_.begin(), includeStack_.end(), canonical) != includeStack_.end())
        element.fail("include cycle: '" + path.string() + "' is already being parsed");
    if (static_cast<int>(includeStack_.size()) >= kMaxIncludeDepth)
        element.fail("includes are nested more than " + std::to_string(kMaxIncludeDepth) + " deep");

    files_.push_back(std::make_unique<xml::XmlFile>(text, path.string(), path.parent_path()));
    const Element root(*files_.back(), files_.back()->root(), defines_);
    if (root.tag() != "scene") root.fail("an included file's root element must be <scene>, not <" + root.tag() + ">");
    root.checkAttributes({"version"});
    includeStack_.push_back(canonical);
    parseSceneChildren(root);
    includeStack_.pop_back();
}

void SceneParser::parseIntegrator(const Element& element) {
    if (integratorAt_)
        element.fail("a scene has only one <integrator> (the first is on line " + std::to_string(integratorAt_->line) +
                     ")");
    const std::string type = pluginType(element, kIntegratorTypes);
    registerId(element);
    const PluginParams params(element, pluginName(element, type), kIntegratorParameters, {});
    IntegratorDescription& integrator = scene_.integrator;
    integrator.type = type;
    if (const auto maxDepth = params.getInteger("maxDepth")) {
        if (*maxDepth != -1 && *maxDepth < 1)
            params.fail("maxDepth", "maxDepth must be -1 (unlimited) or at least 1, got " + std::to_string(*maxDepth));
        integrator.maxDepth = *maxDepth;
    }
    integrator.where = element.where();
    integratorAt_ = integrator.where;
}

void SceneParser::parseSensor(const Element& element) {
    if (sensorAt_)
        element.fail("a scene has only one <sensor> (the first is on line " + std::to_string(sensorAt_->line) + ")");
    const std::string type = pluginType(element, kSensorTypes);
    registerId(element);
    const PluginParams params(element, pluginName(element, type), kPerspectiveParameters,
                              {"film", "sampler", "ref", "medium"});
    SensorDescription& sensor = scene_.sensor;
    sensor.where = element.where();
    sensorAt_ = sensor.where;

    bool haveFilm = false, haveSampler = false;
    for (const Element& child : params.objects()) {
        const std::string tag = child.tag();
        if (tag == "film") {
            if (haveFilm) child.fail("a sensor has only one <film>");
            parseFilm(child, sensor);
            haveFilm = true;
        } else if (tag == "sampler") {
            if (haveSampler) child.fail("a sensor has only one <sampler>");
            parseSampler(child, sensor);
            haveSampler = true;
        } else {
            sensor.medium = mediumChild(child, sensor.medium);
        }
    }

    const auto fov = params.getFloat("fov");
    const auto focalLength = params.getString("focalLength");
    if (fov && focalLength) params.fail("focalLength", "give either 'fov' or 'focalLength', not both");
    const auto fovAxis = params.getString("fovAxis");
    if (fovAxis) {
        const std::string axis = lowercase(*fovAxis);
        const auto it = std::find(std::begin(kFovAxes), std::end(kFovAxes), axis);
        if (it == std::end(kFovAxes))
            params.fail("fovAxis", "unknown fovAxis '" + *fovAxis + "'; valid values: " + xml::joinNames(kFovAxes));
        sensor.fovAxis = static_cast<SensorDescription::FovAxis>(it - std::begin(kFovAxes));
        if (!fov) spdlog::warn("{}: 'fovAxis' only applies together with 'fov'; ignoring it", sensor.where.describe());
    }
    if (fov) {
        if (!(*fov > 0.0f && *fov < 180.0f))
            params.fail("fov", "fov must be in (0, 180) degrees, got " + fmt::format("{}", *fov));
        sensor.fov = *fov;
    } else {
        // Mitsuba: a focal length in 35mm-film equivalent ("50mm" by default) sets the diagonal field of view.
        float millimetres = 50.0f;
        if (focalLength) {
            std::string text = *focalLength;
            if (text.size() > 2 && text.ends_with("mm")) text.resize(text.size() - 2);
            millimetres = xml::parseFloat(*params.element("focalLength"), text, "'focalLength'");
            if (millimetres <= 0.0f)
                params.fail("focalLength", "focalLength must be positive, got '" + *focalLength + "'");
        }
        const double diagonalMm = std::sqrt(36.0 * 36.0 + 24.0 * 24.0);
        sensor.fov = float(2.0 * std::atan(diagonalMm / (2.0 * millimetres)) * 180.0 / std::numbers::pi);
        sensor.fovAxis = SensorDescription::FovAxis::Diagonal;
    }
    if (const auto toWorld = params.getTransform("toWorld")) sensor.toWorld = *toWorld;
    if (const auto nearClip = params.getFloat("nearClip")) {
        if (*nearClip <= 0.0f)
            params.fail("nearClip", "nearClip must be positive, got " + fmt::format("{}", *nearClip));
        sensor.nearClip = *nearClip;
    }
    if (const auto farClip = params.getFloat("farClip")) sensor.farClip = *farClip;
    if (sensor.nearClip >= sensor.farClip)
        element.fail(fmt::format("nearClip ({}) must be smaller than farClip ({})", sensor.nearClip, sensor.farClip));
}

void SceneParser::parseFilm(const Element& element, SensorDescription& sensor) {
    const std::string type = pluginType(element, kFilmTypes);
    registerId(element);
    const PluginParams params(element, pluginName(element, type), kFilmParameters, {"rfilter"});
    for (const Element& child : params.objects())
        spdlog::warn("{}: ignoring the reconstruction filter (not configurable here)", child.where().describe());
    for (const char* name : {"width", "height"}) {
        const auto value = params.getInteger(name);
        if (!value) continue;
        if (*value < 1 || *value > kMaxFilmSide)
            params.fail(name, fmt::format("film {} must be in [1, {}], got {}", name, kMaxFilmSide, *value));
        (std::string_view(name) == "width" ? sensor.width : sensor.height) = *value;
    }
    if (static_cast<long long>(sensor.width) * sensor.height > kMaxFilmPixels)
        element.fail(fmt::format("the film has {} x {} pixels, more than the limit of {}", sensor.width, sensor.height,
                                 kMaxFilmPixels));
}

void SceneParser::parseSampler(const Element& element, SensorDescription& sensor) {
    const std::string type = pluginType(element, kSamplerTypes);
    registerId(element);
    const PluginParams params(element, pluginName(element, type), kSamplerParameters, {});
    if (const auto count = params.getInteger("sampleCount")) {
        if (*count < 1 || *count > kMaxSampleCount)
            params.fail("sampleCount", fmt::format("sampleCount must be in [1, {}], got {}", kMaxSampleCount, *count));
        sensor.sampleCount = *count;
    }
}

BsdfDescription SceneParser::parseBsdf(const Element& element) {
    const std::string type = pluginType(element, kBsdfTypes);
    BsdfDescription bsdf;
    if (type == "diffuse") {
        const PluginParams params(element, pluginName(element, type), kDiffuseParameters, {"texture"});
        if (!params.objects().empty()) params.objects().front().fail("textures are not supported yet");
        bsdf.kind = BsdfDescription::Kind::Diffuse;
        bsdf.reflectance = nonNegativeColor(params, "reflectance", bsdf.reflectance);
        if (maxComponent(bsdf.reflectance) > 1.0f)
            spdlog::warn("{}: reflectance {} exceeds 1 (not energy conserving)", element.where().describe(),
                         formatRgb(bsdf.reflectance));
    } else if (type == "null") {
        const PluginParams params(element, pluginName(element, type), {}, {});
        bsdf.kind = BsdfDescription::Kind::Null;
    } else {  // twosided
        const PluginParams params(element, pluginName(element, type), {}, {"bsdf", "ref"});
        const auto& nested = params.objects();
        if (nested.empty()) element.fail("twosided needs one nested <bsdf> or <ref>");
        if (nested.size() > 1) nested[1].fail("twosided with different front and back bsdfs is not supported yet");
        bsdf = nested[0].tag() == "bsdf" ? parseBsdf(nested[0]) : referencedBsdf(nested[0]);
        if (bsdf.kind == BsdfDescription::Kind::Null)
            nested[0].fail("twosided needs a reflecting bsdf such as diffuse, not null");
        bsdf.twoSided = true;
    }
    registerId(element, bsdf);
    return bsdf;
}

int SceneParser::parseMedium(const Element& element) {
    const std::string type = pluginType(element, kMediumTypes);
    const PluginParams params(element, pluginName(element, type), kHomogeneousParameters, {"phase"});
    MediumDescription medium;
    medium.where = element.where();
    medium.id = element.attribute("id").value_or("");

    const bool hasSA = params.has("sigmaS") || params.has("sigmaA");
    const bool hasTA = params.has("sigmaT") || params.has("albedo");
    if (hasSA && hasTA) element.fail("give either sigmaS and sigmaA, or sigmaT and albedo, not both pairs");
    const auto requirePair = [&](const char* a, const char* b) {
        for (const char* name : {a, b})
            if (!params.has(name)) element.fail(fmt::format("'{}' is missing: give both {} and {}", name, a, b));
    };
    if (hasSA) {
        requirePair("sigmaS", "sigmaA");
        medium.sigmaS = nonNegativeColor(params, "sigmaS", medium.sigmaS);
        medium.sigmaA = nonNegativeColor(params, "sigmaA", medium.sigmaA);
    } else if (hasTA) {
        requirePair("sigmaT", "albedo");
        const Rgb sigmaT = nonNegativeColor(params, "sigmaT", Rgb(1.0f));
        const Rgb albedo = *params.getColor("albedo");
        if (minComponent(albedo) < 0.0f || maxComponent(albedo) > 1.0f)
            params.fail("albedo", "albedo must be in [0, 1], got " + formatRgb(albedo));
        medium.sigmaS = albedo * sigmaT;
        medium.sigmaA = sigmaT - medium.sigmaS;
        medium.sigmaA = {std::max(medium.sigmaA.x, 0.0f), std::max(medium.sigmaA.y, 0.0f),
                         std::max(medium.sigmaA.z, 0.0f)};
    } else {
        spdlog::warn("{}: no sigmaS/sigmaA or sigmaT/albedo given; using sigmaS = sigmaA = 1", medium.where.describe());
    }
    if (const auto scale = params.getFloat("scale")) {
        if (*scale < 0.0f) params.fail("scale", fmt::format("scale must be non-negative, got {}", *scale));
        medium.sigmaS *= *scale;
        medium.sigmaA *= *scale;
    }
    if (!isFinite(medium.sigmaS) || !isFinite(medium.sigmaA))
        element.fail("the scaled coefficients overflow: sigmaS " + formatRgb(medium.sigmaS) + ", sigmaA " +
                     formatRgb(medium.sigmaA));
    const auto& phases = params.objects();
    if (phases.size() > 1) phases[1].fail("a medium has only one <phase>");
    if (!phases.empty()) medium.phase = parsePhase(phases[0]);

    scene_.media.push_back(medium);
    const int index = static_cast<int>(scene_.media.size()) - 1;
    registerId(element, std::nullopt, index);
    return index;
}

PhaseDescription SceneParser::parsePhase(const Element& element) {
    const std::string type = pluginType(element, kPhaseTypes);
    registerId(element);
    PhaseDescription phase;
    if (type == "isotropic") {
        const PluginParams params(element, pluginName(element, type), {}, {});
        return phase;
    }
    const PluginParams params(element, pluginName(element, type), kHgParameters, {});
    phase.kind = PhaseDescription::Kind::HenyeyGreenstein;
    phase.g = params.getFloat("g").value_or(0.8f);  // Mitsuba's default
    if (!(phase.g > -1.0f && phase.g < 1.0f)) params.fail("g", fmt::format("g must be in (-1, 1), got {}", phase.g));
    return phase;
}

void SceneParser::parseShape(const Element& element) {
    const std::string type = pluginType(element, kShapeTypes);
    registerId(element);
    const std::span<const ParamSpec> specs = type == "obj"      ? std::span<const ParamSpec>(kObjParameters)
                                             : type == "sphere" ? std::span<const ParamSpec>(kSphereParameters)
                                                                : std::span<const ParamSpec>(kBasicShapeParameters);
    const PluginParams params(element, pluginName(element, type), specs, {"bsdf", "ref", "emitter", "medium"});
    ShapeDescription shape;
    shape.where = element.where();
    constexpr ShapeDescription::Kind kinds[] = {ShapeDescription::Kind::Obj, ShapeDescription::Kind::Rectangle,
                                                ShapeDescription::Kind::Cube, ShapeDescription::Kind::Sphere,
                                                ShapeDescription::Kind::Disk};
    shape.kind = kinds[std::find(std::begin(kShapeTypes), std::end(kShapeTypes), type) - std::begin(kShapeTypes)];
    if (const auto toWorld = params.getTransform("toWorld")) shape.toWorld = *toWorld;
    shape.flipNormals = params.getBoolean("flipNormals").value_or(false);

    if (type == "obj") {
        const auto filename = params.getString("filename");
        if (!filename) element.fail("missing parameter 'filename' (the .obj file)");
        shape.filename = element.resolvePath(*filename);
        checkReference(element, shape.filename);
        std::error_code error;
        if (!std::filesystem::is_regular_file(shape.filename, error))
            params.fail("filename", "cannot find the OBJ file '" + shape.filename.string() + "'");
        shape.faceNormals = params.getBoolean("faceNormals").value_or(false);
    } else if (type == "sphere") {
        shape.center = params.getPoint("center").value_or(Vec3(0.0f));
        shape.radius = params.getFloat("radius").value_or(1.0f);
        if (shape.radius <= 0.0f) params.fail("radius", fmt::format("radius must be positive, got {}", shape.radius));
    }

    const auto setMedium = [&](const Element& child, const std::string& side, int index) {
        int& slot = side == "interior" ? shape.interiorMedium : shape.exteriorMedium;
        if (slot != -1) child.fail("the shape already has an " + side + " medium");
        slot = index;
    };
    const auto setBsdf = [&](const Element& child, const BsdfDescription& bsdf) {
        if (shape.bsdf) child.fail("a shape has only one bsdf");
        shape.bsdf = bsdf;
    };
    for (const Element& child : params.objects()) {
        const std::string tag = child.tag();
        if (tag == "bsdf") {
            setBsdf(child, parseBsdf(child));
        } else if (tag == "emitter") {
            if (shape.areaRadiance) child.fail("a shape has only one emitter");
            shape.areaRadiance = parseAreaEmitter(child);
        } else if (tag == "medium") {
            const std::string side = child.attribute("name").value_or("");
            if (side != "interior" && side != "exterior")
                child.fail("a <medium> inside a <shape> needs name=\"interior\" or name=\"exterior\"");
            setMedium(child, side, parseMedium(child));
        } else {  // ref
            const std::string name = child.attribute("name").value_or("");
            if (name == "interior" || name == "exterior") {
                setMedium(child, name, referencedMedium(child));
            } else if (name.empty() || name == "bsdf") {
                const Named& named = lookup(child);
                if (named.tag == "medium")
                    child.fail("a medium reference inside a <shape> needs name=\"interior\" or name=\"exterior\"");
                setBsdf(child, referencedBsdf(child));
            } else {
                child.fail("unknown reference name '" + name + "'; valid names: interior, exterior, bsdf");
            }
        }
    }
    scene_.shapes.push_back(std::move(shape));
}

Rgb SceneParser::parseAreaEmitter(const Element& element) {
    const std::string type =
        pluginType(element, kShapeEmitterTypes, " (point and spot emitters go at the top level, outside shapes)");
    registerId(element);
    const PluginParams params(element, pluginName(element, type), kAreaParameters, {});
    return nonNegativeColor(params, "radiance", Rgb(1.0f));
}

EmitterDescription SceneParser::parseEmitter(const Element& element) {
    const std::string type = pluginType(element, kSceneEmitterTypes, " (area emitters go inside a <shape>)");
    registerId(element);
    const bool spot = type == "spot";
    const PluginParams params(
        element, pluginName(element, type),
        spot ? std::span<const ParamSpec>(kSpotParameters) : std::span<const ParamSpec>(kPointParameters),
        {"medium", "ref"});
    EmitterDescription emitter;
    emitter.where = element.where();
    emitter.intensity = nonNegativeColor(params, "intensity", emitter.intensity);
    if (const auto toWorld = params.getTransform("toWorld")) emitter.toWorld = *toWorld;
    if (spot) {
        emitter.kind = EmitterDescription::Kind::Spot;
        emitter.cutoffAngle = params.getFloat("cutoffAngle").value_or(20.0f);
        if (!(emitter.cutoffAngle > 0.0f && emitter.cutoffAngle < 180.0f))
            params.fail("cutoffAngle",
                        fmt::format("cutoffAngle must be in (0, 180) degrees, got {}", emitter.cutoffAngle));
        emitter.beamWidth = params.getFloat("beamWidth").value_or(emitter.cutoffAngle * 3.0f / 4.0f);
        if (!(emitter.beamWidth > 0.0f && emitter.beamWidth <= emitter.cutoffAngle))
            params.fail("beamWidth", fmt::format("beamWidth must be in (0, cutoffAngle = {}] degrees, got {}",
                                                 emitter.cutoffAngle, emitter.beamWidth));
    } else {
        emitter.kind = EmitterDescription::Kind::Point;
        if (const auto position = params.getPoint("position")) {
            if (params.has("toWorld")) params.fail("position", "give either 'position' or 'toWorld', not both");
            emitter.toWorld = Transform::translate(*position);
        }
    }
    for (const Element& child : params.objects()) emitter.medium = mediumChild(child, emitter.medium);
    return emitter;
}

int SceneParser::mediumChild(const Element& child, int current) {
    if (current != -1) child.fail("only one medium may be given here");
    if (child.tag() == "medium") return parseMedium(child);
    return referencedMedium(child);
}

// ---------------------------------------------------------------- ids and references

void SceneParser::registerId(const Element& element, std::optional<BsdfDescription> bsdf, int medium) {
    const auto id = element.attribute("id");
    if (!id) return;
    if (id->empty()) element.fail("an id must not be empty");
    const auto previous = ids_.find(*id);
    if (previous != ids_.end())
        element.fail("duplicate id '" + *id + "' (first used at " + previous->second.where.describe() + ")");
    ids_.emplace(*id, Named{element.tag(), std::move(bsdf), medium, element.where()});
}

const SceneParser::Named& SceneParser::lookup(const Element& ref) {
    ref.checkAttributes({"id", "name"});
    const std::string id = ref.requireAttribute("id");
    const auto it = ids_.find(id);
    if (it == ids_.end()) {
        std::vector<std::string> known;
        for (const auto& [name, named] : ids_)
            if (named.tag == "bsdf" || named.tag == "medium") known.push_back(name + " (" + named.tag + ")");
        ref.fail("unknown id '" + id + "'; " +
                 (known.empty() ? std::string("no bsdf or medium ids are declared before this point")
                                : "known ids: " + xml::joinNames(std::span<const std::string>(known))));
    }
    return it->second;
}

BsdfDescription SceneParser::referencedBsdf(const Element& ref) {
    const Named& named = lookup(ref);
    if (!named.bsdf)
        ref.fail("id '" + ref.requireAttribute("id") + "' names a <" + named.tag + "> (" + named.where.describe() +
                 "), not a <bsdf>");
    return *named.bsdf;
}

int SceneParser::referencedMedium(const Element& ref) {
    const Named& named = lookup(ref);
    if (named.medium < 0)
        ref.fail("id '" + ref.requireAttribute("id") + "' names a <" + named.tag + "> (" + named.where.describe() +
                 "), not a <medium>");
    return named.medium;
}

}  // namespace

// ---------------------------------------------------------------- public API

SceneDescription parseMitsubaScene(const std::filesystem::path& file, const ParseOptions& options) {
    if (options.onFileReferenced) options.onFileReferenced(file);
    const std::string text = xml::readTextFile(file, {file.string(), 0, ""}, "scene file");
    auto xmlFile = std::make_unique<xml::XmlFile>(text, file.string(), file.parent_path());
    std::error_code error;
    return SceneParser(options).parse(std::move(xmlFile), file, std::filesystem::weakly_canonical(file, error));
}

SceneDescription parseMitsubaSceneString(const std::string& xml, const std::filesystem::path& baseDirectory,
                                         const ParseOptions& options, const std::string& virtualFileName) {
    auto xmlFile = std::make_unique<xml::XmlFile>(xml, virtualFileName, baseDirectory);
    return SceneParser(options).parse(std::move(xmlFile), virtualFileName, std::nullopt);
}

}  // namespace vrl
