#include "render/image/exr_io.h"

#include "util/atomic_file.h"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfName.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <deque>
#include <vector>
#include <climits>
#include <cstdint>
#include <fstream>
#include <set>
#include <stdexcept>
#include <system_error>
#include <variant>

namespace vrl {
namespace {

static_assert(sizeof(Rgb) == 3 * sizeof(float), "slices assume Rgb is three packed floats");

constexpr std::array<const char*, 3> kComponents = {"R", "G", "B"};
constexpr size_t kMaxNameLength = Imf::Name::MAX_LENGTH;  // longer names are truncated by OpenEXR

// The string attribute that tells OpenEXR how a part is stored (e.g. "tiledimage");
// it is file structure, not metadata.
constexpr const char* kPartTypeKey = "type";

std::string quoted(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

// The float slice for one component (0 = R, 1 = G, 2 = B) of `image`, laid out
// over `dataWindow` (which may have any offset).
Imf::Slice componentSlice(const Image& image, int component, const Imath::Box2i& dataWindow) {
    return Imf::Slice::Make(Imf::FLOAT, &image[0][component], dataWindow, sizeof(Rgb));
}

void checkWritable(const std::filesystem::path& path, const ImageSet& images) {
    auto fail = [&](const std::string& problem) {
        throw std::invalid_argument("cannot write EXR " + quoted(path) + ": " + problem);
    };
    const Image& image = images.image;
    if (image.pixelCount() == 0) fail("the image is empty");
    std::set<std::string> names;
    for (const auto& [name, layer] : images.layers) {
        if (name.empty()) fail("a layer has an empty name");
        if (name.size() + 2 > kMaxNameLength) fail("layer name '" + name + "' is too long for an EXR channel");
        if (!names.insert(name).second) fail("duplicate layer '" + name + "'");
        if (layer.width() != image.width() || layer.height() != image.height())
            fail("layer '" + name + "' is " + std::to_string(layer.width()) + "x" + std::to_string(layer.height()) +
                 " but the image is " + std::to_string(image.width()) + "x" + std::to_string(image.height()));
    }
    for (const auto& name : images.singleChannelLayers)
        if (!names.count(name)) fail("single-channel layer '" + name + "' is not among the layers");
    for (const auto& entry : images.metadata) {
        if (entry.first.empty() || entry.first.size() > kMaxNameLength)
            fail("metadata key '" + entry.first + "' must have 1 to " + std::to_string(kMaxNameLength) + " characters");
        if (entry.first == kPartTypeKey) fail("metadata key 'type' is reserved by OpenEXR for the part type");
    }
}

ImageSet readExrFile(const std::filesystem::path& path) {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const Imath::Box2i dataWindow = header.dataWindow();
    const int64_t width = int64_t(dataWindow.max.x) - dataWindow.min.x + 1;
    const int64_t height = int64_t(dataWindow.max.y) - dataWindow.min.y + 1;
    if (width <= 0 || height <= 0 || width > INT_MAX || height > INT_MAX)
        throw std::runtime_error("unsupported data window size " + std::to_string(width) + "x" + std::to_string(height));

    ImageSet result;
    result.image = Image(int(width), int(height));
    Imf::FrameBuffer frameBuffer;
    const Imf::ChannelList& channels = header.channels();

    std::string missing;  // e.g. "G, B"
    int missingCount = 0;
    for (const char* name : kComponents) {
        if (channels.findChannel(name)) continue;
        missing += (missingCount++ == 0 ? "" : ", ") + std::string(name);
    }
    const bool grey = missingCount == 3 && channels.findChannel("Y");
    if (grey) {
        if (channels.findChannel("RY") || channels.findChannel("BY"))
            throw std::runtime_error("luminance/chroma images (channels Y, RY, BY) are not supported");
        frameBuffer.insert("Y", componentSlice(result.image, 0, dataWindow));
    } else if (!missing.empty()) {
        throw std::runtime_error("missing channel(s) " + missing);
    } else {
        for (int c = 0; c < 3; ++c) frameBuffer.insert(kComponents[c], componentSlice(result.image, c, dataWindow));
    }

    std::set<std::string> layerNames;  // prefixes up to the last '.', sorted
    channels.layers(layerNames);
    for (const std::string& name : layerNames) {
        bool complete = true;
        for (const char* component : kComponents) complete = complete && channels.findChannel(name + "." + component);
        if (complete) {
            result.layers.emplace_back(name, Image(int(width), int(height)));
        } else if (channels.findChannel(name + ".Y") && !channels.findChannel(name + ".R") &&
                   !channels.findChannel(name + ".G") && !channels.findChannel(name + ".B")) {
            result.layers.emplace_back(name, Image(int(width), int(height)));
            result.singleChannelLayers.insert(name);
        }
    }
    for (const auto& [name, layer] : result.layers) {
        if (result.singleChannelLayers.count(name)) {
            frameBuffer.insert(name + ".Y", componentSlice(layer, 0, dataWindow));
            continue;
        }
        for (int c = 0; c < 3; ++c) frameBuffer.insert(name + "." + kComponents[c], componentSlice(layer, c, dataWindow));
    }

    file.setFrameBuffer(frameBuffer);
    file.readPixels(dataWindow.min.y, dataWindow.max.y);
    if (grey)
        for (size_t i = 0; i < result.image.pixelCount(); ++i) result.image[i] = Rgb(result.image[i].x);
    for (auto& [name, layer] : result.layers)
        if (result.singleChannelLayers.count(name))
            for (size_t i = 0; i < layer.pixelCount(); ++i) layer[i] = Rgb(layer[i].x);

    for (auto it = header.begin(); it != header.end(); ++it) {
        const std::string name = it.name();
        const Imf::Attribute& attribute = it.attribute();
        if (const auto* text = dynamic_cast<const Imf::StringAttribute*>(&attribute)) {
            if (name != kPartTypeKey) result.metadata[name] = text->value();
        } else if (name.rfind("vrl.", 0) == 0 || name == "worldToCamera" || name == "worldToNDC") {
            // Numbers and matrices of ours (OpenEXR's own, such as pixelAspectRatio, stay out).
            if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&attribute)) result.metadata[name] = int32_t(i->value());
            if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&attribute)) result.metadata[name] = f->value();
            if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&attribute)) result.metadata[name] = d->value();
            if (const auto* m = dynamic_cast<const Imf::M44fAttribute*>(&attribute)) result.metadata[name] = m->value();
        }
    }
    return result;
}

}  // namespace

void writeExr(const std::filesystem::path& path, const ImageSet& images, ExrPixels pixels) {
    checkWritable(path, images);
    const Image& image = images.image;
    const Imf::PixelType type = pixels == ExrPixels::Half ? Imf::HALF : Imf::FLOAT;
    if (pixels == ExrPixels::Half) {
        constexpr float kHalfMax = 65504.0f;
        const auto check = [&](const std::string& what, const Image& source) {
            for (size_t i = 0; i < source.pixelCount(); ++i)
                for (int c = 0; c < 3; ++c)
                    if (std::isfinite(source[i][c]) && std::abs(source[i][c]) > kHalfMax)
                        throw std::invalid_argument("cannot write " + quoted(path) + " in half precision: " + what +
                                                    " has a value beyond 65504 (write it in float)");
        };
        check("the image", image);
        for (const auto& [name, layer] : images.layers) check("layer " + name, layer);
    }
    Imf::Header header(image.width(), image.height());  // data and display window at the origin
    header.compression() = Imf::ZIP_COMPRESSION;
    const Imath::Box2i dataWindow = header.dataWindow();
    Imf::FrameBuffer frameBuffer;
    std::deque<std::vector<half>> halfPlanes;  // Half: the converted channels (OpenEXR does not convert on write)
    const auto slice = [&](const Image& source, int c) {
        if (pixels == ExrPixels::Float) return componentSlice(source, c, dataWindow);
        auto& plane = halfPlanes.emplace_back(source.pixelCount());
        for (size_t i = 0; i < plane.size(); ++i) plane[i] = half(source[i][c]);
        return Imf::Slice::Make(Imf::HALF, plane.data(), dataWindow);
    };
    auto addRgb = [&](const std::string& prefix, const Image& source) {
        for (int c = 0; c < 3; ++c) {
            header.channels().insert(prefix + kComponents[c], Imf::Channel(type));
            frameBuffer.insert(prefix + kComponents[c], slice(source, c));
        }
    };
    addRgb("", image);
    for (const auto& [name, layer] : images.layers) {
        if (images.singleChannelLayers.count(name)) {
            header.channels().insert(name + ".Y", Imf::Channel(type));
            frameBuffer.insert(name + ".Y", slice(layer, 0));
        } else {
            addRgb(name + ".", layer);
        }
    }

    try {
        // A key naming a standard attribute of another type (e.g. "channels") throws here.
        for (const auto& [key, value] : images.metadata) {
            struct Insert {
                Imf::Header& header;
                const std::string& key;
                void operator()(const std::string& v) const { header.insert(key, Imf::StringAttribute(v)); }
                void operator()(int32_t v) const { header.insert(key, Imf::IntAttribute(v)); }
                void operator()(float v) const { header.insert(key, Imf::FloatAttribute(v)); }
                void operator()(double v) const { header.insert(key, Imf::DoubleAttribute(v)); }
                void operator()(const Imath::M44f& v) const { header.insert(key, Imf::M44fAttribute(v)); }
            };
            std::visit(Insert{header, key}, value);
        }
        util::writeAtomically(path, [&](const std::filesystem::path& temporary) {
            std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
            if (!out)
                throw std::runtime_error("cannot create " + quoted(temporary) + ": " +
                                         std::generic_category().message(errno));
            {
                Imf::StdOFStream stream(out, temporary.c_str());
                Imf::OutputFile file(stream, header);
                file.setFrameBuffer(frameBuffer);
                file.writePixels(image.height());
            }  // the destructor writes the line offset table; a failure there shows in `out`
            out.close();
            if (!out) throw std::runtime_error("error writing " + quoted(temporary));
        });
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write EXR " + quoted(path) + ": " + e.what());
    }
}

ImageSet readExr(const std::filesystem::path& path) {
    try {
        return readExrFile(path);
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read EXR " + quoted(path) + ": " + e.what());
    }
}

}  // namespace vrl
