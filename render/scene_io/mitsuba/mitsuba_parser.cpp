#include "render/scene_io/mitsuba/mitsuba_parser.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <numbers>
#include <set>

#include "render/scene_io/mitsuba/mitsuba_bsdf_parser.h"
#include "render/scene_io/mitsuba/mitsuba_parse_context.h"
#include "render/scene_io/mitsuba/xml_values.h"
#include "util/strings.h"

namespace vrl {
namespace {

using mitsuba::formatRgb;
using mitsuba::NamedObject;
using mitsuba::nonNegativeColor;
using mitsuba::pluginName;
using mitsuba::pluginType;
using xml::Element;
using xml::ParamSpec;
using xml::PluginParams;

// ---------------------------------------------------------------- plugin tables
// Each plugin's parameters and how they are used; extend a table to accept more.
// Bsdfs and textures: mitsuba_bsdf_parser.cpp.
using T = xml::ParamType;
using U = xml::ParamUse;
// clang-format off
// Integrators this renderer implements: the path tracer's Mitsuba names and
// the rendering methods' own names (renderer.h: path, vrl, vrl-lightcuts,
// vrl-stochastic, vpl, vpl-lightcuts; a job with no method renders the one its scene names), then the
// other Mitsuba 0.5/0.6 integrators: accepted, their parameters listed in
// SceneDescription::ignored, only maxDepth read.
constexpr std::string_view kIntegratorTypes[] = {
    "volpath", "volpath_simple", "path", "direct", "vrl", "vrlcuts", "vrl-lightcuts", "vrl-stochastic", "vpl",
    "vpl-lightcuts", "ao", "bdpt", "photonmapper", "ppm", "sppm", "pssmlt", "mlt", "erpt", "ptracer",
    "adaptive", "irrcache", "multichannel", "field"};
constexpr size_t kOwnIntegratorCount = 10;
constexpr ParamSpec kIntegratorParameters[] = {
    {"maxDepth", T::Integer}, {"rrDepth", T::Integer, U::Ignore},
    {"strictNormals", T::Boolean, U::Ignore}, {"hideEmitters", T::Boolean, U::Ignore},
    {"version", T::Integer, U::Ignore},  // lajolla's integrator version tag
    {"shadowMapResolution", T::Integer, U::Ignore}, {"clamping", T::Float, U::Ignore}};  // Mitsuba's vpl

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
    {"cropOffsetX", T::Integer}, {"cropOffsetY", T::Integer}, {"cropWidth", T::Integer}, {"cropHeight", T::Integer}};
constexpr std::string_view kRfilterTypes[] = {"box", "tent", "gaussian", "mitchell", "catmullrom", "lanczos"};
constexpr ParamSpec kRfilterParameters[] = {
    {"radius", T::Float, U::Ignore}, {"stddev", T::Float, U::Ignore}, {"B", T::Float, U::Ignore},
    {"C", T::Float, U::Ignore}, {"lobes", T::Integer, U::Ignore}};

// All treated as independent sampling with `sampleCount` samples per pixel.
constexpr std::string_view kSamplerTypes[] = {"independent", "ldsampler", "stratified", "halton", "sobol"};
constexpr ParamSpec kSamplerParameters[] = {
    {"sampleCount", T::Integer}, {"scramble", T::Integer, U::Ignore}, {"dimension", T::Integer, U::Ignore}};

// In ShapeDescription::Kind order.
constexpr std::string_view kShapeTypes[] = {"obj", "rectangle", "cube", "sphere", "disk", "serialized"};
constexpr ParamSpec kBasicShapeParameters[] = {{"toWorld", T::Transform}, {"flipNormals", T::Boolean}};
constexpr ParamSpec kSphereParameters[] = {
    {"toWorld", T::Transform}, {"flipNormals", T::Boolean}, {"center", T::Point}, {"radius", T::Float}};
constexpr ParamSpec kObjParameters[] = {
    {"filename", T::String}, {"toWorld", T::Transform}, {"flipNormals", T::Boolean}, {"faceNormals", T::Boolean},
    {"flipTexCoords", T::Boolean}, {"maxSmoothAngle", T::Float, U::Unsupported}};
constexpr ParamSpec kSerializedParameters[] = {
    {"filename", T::String}, {"shapeIndex", T::Integer}, {"toWorld", T::Transform}, {"flipNormals", T::Boolean},
    {"faceNormals", T::Boolean}, {"maxSmoothAngle", T::Float, U::Ignore}};

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
    "default", "include", "integrator", "sensor", "shape", "bsdf", "texture", "medium", "emitter"};
constexpr std::string_view kFovAxes[] = {"x", "y", "diagonal", "smaller", "larger"};  // FovAxis order
// clang-format on

constexpr int kMaxIncludeDepth = 64;
constexpr const char* kSamplingWeightReason = "emitters are chosen by power (light tree), not by samplingWeight";

// Mitsuba's maxDepth: -1 (unlimited) or a path length of at least 1.
void checkMaxDepth(const Element& at, int maxDepth) {
    if (maxDepth != -1 && maxDepth < 1)
        at.fail("maxDepth must be -1 (unlimited) or at least 1, got " + std::to_string(maxDepth));
}

// ---------------------------------------------------------------- the parser

class SceneParser {
public:
    explicit SceneParser(const ParseOptions& options)
        : defines_(options.defines.begin(), options.defines.end()),
          commandLineDefines_(options.defines),
          context_(options) {}

    SceneDescription parse(std::unique_ptr<xml::XmlFile> file, const std::filesystem::path& identity,
                           std::optional<std::filesystem::path> canonicalPath);

private:
    void parseSceneChildren(const Element& scene);
    void parseDefault(const Element& element);
    void parseInclude(const Element& element);
    void parseIntegrator(const Element& element);
    // Mitsuba integrators this renderer does not implement: accepts any
    // parameters (listed in `parameters`) and nested integrators.
    void parseForeignIntegrator(const Element& element, const std::string& prefix, std::vector<std::string>& parameters,
                                std::optional<int>& maxDepth);
    void parseSensor(const Element& element);
    void parseFilm(const Element& element, SensorDescription& sensor);
    void parseSampler(const Element& element, SensorDescription& sensor);
    int parseMedium(const Element& element);
    PhaseDescription parsePhase(const Element& element);
    void parseShape(const Element& element);
    Rgb parseAreaEmitter(const Element& element);
    EmitterDescription parseEmitter(const Element& element);

    void registerId(const Element& element, NamedObject object = {}) {
        context_.registerId(element, std::move(object));
    }
    int referencedMedium(const Element& ref);
    int mediumChild(const Element& child, int current);  // nested <medium> or <ref> to one
    // Keeps a loaded file alive and notes the $names it mentions.
    const xml::XmlFile& addFile(std::unique_ptr<xml::XmlFile> file);
    // Fails on a -D define that no <default> declares and no $name uses.
    void checkDefinesUsed() const;

    xml::Defines defines_;
    std::map<std::string, std::string> commandLineDefines_;
    std::set<std::string> defaultNames_, references_;  // <default name=...> and every $identifier, in all files
    mitsuba::ParseContext context_;
    SceneDescription& scene_ = context_.scene();
    std::vector<std::unique_ptr<xml::XmlFile>> files_;  // alive while their elements are in use
    std::vector<std::filesystem::path> includeStack_;   // canonical paths, for cycle detection
    std::optional<SourceLocation> sensorAt_, integratorAt_;
};

SceneDescription SceneParser::parse(std::unique_ptr<xml::XmlFile> file, const std::filesystem::path& identity,
                                    std::optional<std::filesystem::path> canonicalPath) {
    const xml::XmlFile& sceneFile = addFile(std::move(file));
    const Element root(sceneFile, sceneFile.root(), defines_);
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
    checkDefinesUsed();

    if (!sensorAt_) spdlog::warn("{}: the scene has no <sensor>; using the default camera", identity.string());
    if (!integratorAt_)
        spdlog::debug("{}: the scene has no <integrator>; using {}", identity.string(), scene_.integrator.type);
    return context_.finish();
}

const xml::XmlFile& SceneParser::addFile(std::unique_ptr<xml::XmlFile> file) {
    references_.merge(xml::parameterReferences(*file));
    files_.push_back(std::move(file));
    return *files_.back();
}

void SceneParser::checkDefinesUsed() const {
    std::set<std::string> used = defaultNames_;
    for (const std::string& identifier : references_)
        if (const auto name = xml::resolveParameter(identifier, defines_)) used.insert(*name);
    std::string problems;
    for (const auto& [name, value] : commandLineDefines_) {
        if (used.contains(name)) continue;
        problems += (problems.empty() ? "" : "; ") +
                    fmt::format("-D {}={}: the scene uses no ${} and has no <default name=\"{}\">", util::abbreviate(name),
                                util::abbreviate(value), util::abbreviate(name), util::abbreviate(name));
    }
    if (problems.empty()) return;
    std::set<std::string> names = defaultNames_;
    names.insert(references_.begin(), references_.end());
    const std::vector<std::string> list(names.begin(), names.end());
    throw SceneError({scene_.file.string(), 0, ""},
                     problems + (list.empty() ? "; it uses no $names" : "; names it uses: " + xml::joinNames(list)));
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
        } else if (tag == "bsdf" || tag == "texture" || tag == "medium") {
            if (tag == "bsdf") mitsuba::parseBsdf(context_, child);
            if (tag == "texture") mitsuba::parseTexture(context_, child);
            if (tag == "medium") parseMedium(child);
            if (!child.has("id"))
                spdlog::warn("{}: a top-level <{}> without an id is never used", child.where().describe(), tag);
        } else if (tag == "emitter") {
            if (util::toLower(child.attribute("type").value_or("")) == "area")
                child.fail("attach area emitters to a shape (put the <emitter type=\"area\"> inside a <shape>)");
            scene_.emitters.push_back(parseEmitter(child));
        } else {
            child.fail("unknown element <" + tag + "> in <scene>; valid here: " + xml::joinNames(kSceneChildren));
        }
    }
}

void SceneParser::parseDefault(const Element& element) {
    element.checkAttributes({"name", "value"});
    const std::string name = element.requireAttribute("name");
    const bool identifier = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    });
    if (!identifier) element.fail("invalid parameter name '" + name + "' (use letters, digits and '_')");
    const std::string value = element.requireAttribute("value");
    defaultNames_.insert(name);
    defines_.try_emplace(name, value);  // a -D define or an earlier <default> wins
}

void SceneParser::parseInclude(const Element& element) {
    element.checkAttributes({"filename"});
    const std::filesystem::path path = element.resolvePath(element.requireAttribute("filename"));
    context_.checkReference(element, path);
    const std::string text = xml::readTextFile(path, element.where(), "included file", kMaxSceneFileBytes);
    std::error_code error;
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, error);
    if (std::find(includeStack_.begin(), includeStack_.end(), canonical) != includeStack_.end())
        element.fail("include cycle: '" + path.string() + "' is already being parsed");
    if (static_cast<int>(includeStack_.size()) >= kMaxIncludeDepth)
        element.fail("includes are nested more than " + std::to_string(kMaxIncludeDepth) + " deep");

    const xml::XmlFile& included = addFile(std::make_unique<xml::XmlFile>(text, path.string(), path.parent_path()));
    const Element root(included, included.root(), defines_);
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
    IntegratorDescription& integrator = scene_.integrator;
    integrator.type = type;
    integrator.where = element.where();
    integratorAt_ = integrator.where;
    const bool own = std::find(std::begin(kIntegratorTypes), std::begin(kIntegratorTypes) + kOwnIntegratorCount,
                               type) != std::begin(kIntegratorTypes) + kOwnIntegratorCount;
    std::optional<int> maxDepth;
    if (own) {
        const PluginParams params(element, pluginName(element, type), kIntegratorParameters, {});
        context_.reportIgnoredParameters(params, element, type, "no effect in this renderer");
        maxDepth = params.getInteger("maxDepth");
        if (maxDepth) checkMaxDepth(*params.element("maxDepth"), *maxDepth);
    } else {
        std::vector<std::string> parameters;
        parseForeignIntegrator(element, "", parameters, maxDepth);
        context_.reportIgnored(element, type, "rendering uses --method; only maxDepth is read", parameters);
    }
    if (maxDepth) integrator.maxDepth = *maxDepth;
}

void SceneParser::parseForeignIntegrator(const Element& element, const std::string& prefix,
                                         std::vector<std::string>& parameters, std::optional<int>& maxDepth) {
    std::optional<int> nestedMaxDepth;
    for (const Element& child : element.children()) {
        const std::string tag = child.tag();
        if (tag == "integrator") {  // adaptive, irrcache, multichannel wrap others
            const std::string type = pluginType(child, kIntegratorTypes);
            registerId(child);
            parameters.push_back(prefix + "integrator '" + type + "'");
            parseForeignIntegrator(child, prefix + type + ".", parameters, nestedMaxDepth);
        } else if (xml::isValueTag(tag)) {
            const std::string name = child.requireAttribute("name");
            if (name != "maxDepth") {
                parameters.push_back(prefix + name);
                continue;
            }
            if (tag != "integer") child.fail("parameter 'maxDepth' must be given as <integer>, not <" + tag + ">");
            if (maxDepth) child.fail("parameter 'maxDepth' is given twice");
            child.checkAttributes({"name", "value"});
            maxDepth = xml::parseInteger(child, child.requireAttribute("value"), "'maxDepth'");
            checkMaxDepth(child, *maxDepth);
        } else {
            child.fail("unknown element <" + tag + "> in integrator; valid here: a value element (integer, float, " +
                       "boolean, string, ...) or a nested <integrator>");
        }
    }
    if (!maxDepth) maxDepth = nestedMaxDepth;  // the wrapped integrator's depth applies
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
        const std::string axis = util::toLower(*fovAxis);
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
    context_.reportIgnoredParameters(
        params, element, type, "a pinhole camera with an instantaneous shutter: no depth of field or motion blur");
    if (sensor.nearClip >= sensor.farClip)
        element.fail(fmt::format("nearClip ({}) must be smaller than farClip ({})", sensor.nearClip, sensor.farClip));
}
void SceneParser::parseFilm(const Element& element, SensorDescription& sensor) {
    const std::string type = pluginType(element, kFilmTypes);
    registerId(element);
    const PluginParams params(element, pluginName(element, type), kFilmParameters, {"rfilter"});
    const std::string outputReason =
        "the result is a linear-RGB high-dynamic-range image; output settings have no "
        "effect";
    if (type == "ldrfilm") context_.reportIgnored(element, type, outputReason);
    context_.reportIgnoredParameters(params, element, type, outputReason);
    if (params.objects().size() > 1) params.objects()[1].fail("a film has only one <rfilter>");
    for (const Element& child : params.objects()) {
        const std::string filter = pluginType(child, kRfilterTypes);
        registerId(child);
        const PluginParams filterParams(child, pluginName(child, filter), kRfilterParameters, {});
        const auto parameters = filterParams.ignoredParameters();
        if (filter != "box" || !parameters.empty())  // Mitsuba's default box filter is what happens here
            context_.reportIgnored(child, filter,
                                   "reconstruction filter: pixels are box-filtered (each averages its own samples)",
                                   parameters);
    }
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
    // Mitsuba's crop window: offsets default to 0, the size to the film's.
    if (params.has("cropOffsetX") || params.has("cropOffsetY") || params.has("cropWidth") || params.has("cropHeight")) {
        const FilmCrop crop{params.getInteger("cropOffsetX").value_or(0), params.getInteger("cropOffsetY").value_or(0),
                            params.getInteger("cropWidth").value_or(sensor.width),
                            params.getInteger("cropHeight").value_or(sensor.height)};
        try {
            sensor.crop = checkFilmCrop(crop, sensor.width, sensor.height);
        } catch (const std::invalid_argument& e) {
            element.fail(fmt::format("cropOffsetX {}, cropOffsetY {}, cropWidth {}, cropHeight {}: {}", crop.x0,
                                     crop.y0, crop.width, crop.height, e.what()));
        }
    }
}

void SceneParser::parseSampler(const Element& element, SensorDescription& sensor) {
    const std::string type = pluginType(element, kSamplerTypes);
    registerId(element);
    const PluginParams params(element, pluginName(element, type), kSamplerParameters, {});
    const std::string reason = "camera samples are independent random numbers (sampleCount is used)";
    if (type != "independent") context_.reportIgnored(element, type, reason);
    context_.reportIgnoredParameters(params, element, type, reason);
    if (const auto count = params.getInteger("sampleCount")) {
        if (*count < 1 || *count > kMaxSampleCount)
            params.fail("sampleCount", fmt::format("sampleCount must be in [1, {}], got {}", kMaxSampleCount, *count));
        sensor.sampleCount = *count;
    }
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
    registerId(element, NamedObject::ofMedium(index));
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
    const std::span<const ParamSpec> specs = type == "obj"          ? std::span<const ParamSpec>(kObjParameters)
                                             : type == "serialized" ? std::span<const ParamSpec>(kSerializedParameters)
                                             : type == "sphere"     ? std::span<const ParamSpec>(kSphereParameters)
                                                                    : std::span<const ParamSpec>(kBasicShapeParameters);
    const std::string plugin = pluginName(element, type);
    const PluginParams params(element, plugin, specs, {"bsdf", "ref", "emitter", "medium"});
    ShapeDescription shape;
    shape.where = element.where();
    constexpr ShapeDescription::Kind kinds[] = {ShapeDescription::Kind::Obj,  ShapeDescription::Kind::Rectangle,
                                                ShapeDescription::Kind::Cube, ShapeDescription::Kind::Sphere,
                                                ShapeDescription::Kind::Disk, ShapeDescription::Kind::Serialized};
    shape.kind = kinds[std::find(std::begin(kShapeTypes), std::end(kShapeTypes), type) - std::begin(kShapeTypes)];
    if (const auto toWorld = params.getTransform("toWorld")) shape.toWorld = *toWorld;
    shape.flipNormals = params.getBoolean("flipNormals").value_or(false);

    if (type == "obj") {
        shape.filename = context_.requireFile(params, element, "filename", "OBJ file");
        shape.faceNormals = params.getBoolean("faceNormals").value_or(false);
        shape.flipTexCoords = params.getBoolean("flipTexCoords").value_or(true);
        context_.reportIgnoredParameters(params, element, type, "no effect in this renderer");
    } else if (type == "serialized") {
        shape.filename = context_.requireFile(params, element, "filename", "serialized mesh file");
        shape.shapeIndex = params.getInteger("shapeIndex").value_or(0);
        if (shape.shapeIndex < 0)
            params.fail("shapeIndex", fmt::format("shapeIndex must be at least 0, got {}", shape.shapeIndex));
        shape.faceNormals = params.getBoolean("faceNormals").value_or(false);
        if (shape.faceNormals && params.has("maxSmoothAngle"))
            params.fail("maxSmoothAngle", "give either 'faceNormals' or 'maxSmoothAngle', not both");
        if (params.has("maxSmoothAngle"))
            context_.reportIgnored(element, type, "normals are used as stored in the file, not re-smoothed by angle",
                                   params.ignoredParameters(), /*warn=*/true);
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
        context_.useBsdf(bsdf);
    };
    for (const Element& child : params.objects()) {
        const std::string tag = child.tag();
        if (tag == "bsdf") {
            setBsdf(child, mitsuba::parseBsdf(context_, child));
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
                const NamedObject& named = context_.lookup(child);
                if (named.tag == "medium")
                    child.fail("a medium reference inside a <shape> needs name=\"interior\" or name=\"exterior\"");
                setBsdf(child, context_.referencedBsdf(child));
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
    context_.reportIgnoredParameters(params, element, type, kSamplingWeightReason);
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
    context_.reportIgnoredParameters(params, element, type, kSamplingWeightReason);
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

int SceneParser::referencedMedium(const Element& ref) {
    const NamedObject& named = context_.lookup(ref);
    if (named.medium < 0)
        ref.fail("id '" + ref.requireAttribute("id") + "' names a <" + named.tag + "> (" + named.where.describe() +
                 "), not a <medium>");
    return named.medium;
}

}  // namespace

// ---------------------------------------------------------------- public API

SceneDescription parseMitsubaScene(const std::filesystem::path& file, const ParseOptions& options) {
    if (options.onFileReferenced) options.onFileReferenced(file);
    const std::string text = xml::readTextFile(file, {file.string(), 0, ""}, "scene file", kMaxSceneFileBytes);
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
