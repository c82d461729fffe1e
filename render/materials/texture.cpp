// Texture: loading (OpenImageIO), linearisation and bilinear lookup.
//
// Storage: texels_ holds width x height linear Rgb values, row 0 = the BOTTOM row
// of the image, so that texel (x, y) covers uv in [x, x+1)/width x [y, y+1)/height.
// Scanline files are decoded in strips of their own 8/16-bit or float type and
// linearised into that array row by row (8/16-bit through a table of all codes),
// so loading needs 12 bytes per texel plus a few MB. Lookups follow Mitsuba 0.5's
// MIPMap::evalBilinear: texel centres sit at (x + 0.5) / width, and each of the
// four texels is fetched through the wrap mode.
#include "render/materials/texture.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>

namespace vrl {
namespace {

constexpr int kMaxTextureSide = 32768;
constexpr long long kMaxTextureTexels = 1LL << 28;

// The sRGB electro-optical transfer function (IEC 61966-2-1), exact form.
float srgbToLinear(float c) {
    const float a = std::abs(c);
    const float linear = a <= 0.04045f ? a / 12.92f : std::pow((a + 0.055f) / 1.055f, 2.4f);
    return std::copysign(linear, c);
}

// How stored values map to linear ones.
struct Transfer {
    enum class Kind { Linear, Srgb, Power };
    Kind kind = Kind::Linear;
    float gamma = 1.0f;

    // Negative stored values (possible in float images) become 0: a texture is a
    // reflectance and must not make a path's throughput negative.
    float operator()(float c) const {
        c = std::max(c, 0.0f);
        switch (kind) {
        case Kind::Linear: return c;
        case Kind::Srgb: return srgbToLinear(c);
        case Kind::Power: return std::pow(c, gamma);
        }
        return c;
    }
};

Transfer transferFor(const TextureDescription& description, bool integerFormat) {
    if (!description.gamma) return {integerFormat ? Transfer::Kind::Srgb : Transfer::Kind::Linear, 1.0f};
    const float gamma = *description.gamma;
    if (gamma == -1.0f) return {Transfer::Kind::Srgb, 1.0f};
    if (!(gamma > 0.0f) || !std::isfinite(gamma))
        throw SceneError(description.where, "texture '" + description.filename.string() +
                                                "': gamma must be positive or -1 (sRGB), got " + std::to_string(gamma));
    if (gamma == 1.0f) return {Transfer::Kind::Linear, 1.0f};
    return {Transfer::Kind::Power, gamma};
}

// Stored component -> linear value: a table of all codes for 8- and 16-bit
// unsigned files (no pow per component), the transfer function otherwise;
// non-finite results become 0.
class Linearizer {
public:
    Linearizer(const Transfer& transfer, OIIO::TypeDesc::BASETYPE stored) : transfer_(transfer) {
        const int maxCode = stored == OIIO::TypeDesc::UINT8 ? 255 : stored == OIIO::TypeDesc::UINT16 ? 65535 : 0;
        table_.resize(size_t(maxCode) + 1);
        for (int k = 0; k <= maxCode && maxCode > 0; ++k) table_[size_t(k)] = transfer(float(k) / float(maxCode));
    }
    float operator()(uint8_t code) const { return table_[code]; }
    float operator()(uint16_t code) const { return table_[code]; }
    float operator()(float value) const {
        const float v = transfer_(value);
        return std::isfinite(v) ? v : 0.0f;
    }

private:
    Transfer transfer_;
    std::vector<float> table_;
};

// Decodes a scanline file in strips of about a million components of type T
// (OIIO converting the file's type to T), linearising into `texels` with rows
// flipped: file row 0 (top) becomes the last stored row. `channels` is 1 (grey,
// replicated) or 3. Returns false on a read error (input->geterror() says why).
template <typename T>
bool readStrips(OIIO::ImageInput& input, int channels, OIIO::TypeDesc type, const Linearizer& linear,
                std::vector<Rgb>& texels) {
    const OIIO::ImageSpec& spec = input.spec();
    const int width = spec.width, height = spec.height;
    const int rowsPerStrip = std::clamp((1 << 20) / (width * channels), 1, height);
    std::vector<T> strip(size_t(width) * size_t(channels) * size_t(rowsPerStrip));
    for (int y0 = 0; y0 < height; y0 += rowsPerStrip) {
        const int y1 = std::min(height, y0 + rowsPerStrip);
        if (!input.read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, channels, type, strip.data()))
            return false;
        for (int y = y0; y < y1; ++y) {
            const T* src = &strip[size_t(y - y0) * size_t(width) * size_t(channels)];
            Rgb* dst = &texels[size_t(height - 1 - y) * size_t(width)];
            if (channels == 1)
                for (int x = 0; x < width; ++x) dst[x] = Rgb(linear(src[x]));
            else
                for (int x = 0; x < width; ++x, src += 3) dst[x] = Rgb(linear(src[0]), linear(src[1]), linear(src[2]));
        }
    }
    return true;
}

// Decodes a tiled file at once as float straight into `texels` (a negative
// scanline stride flips the rows), then linearises in place.
bool readWhole(OIIO::ImageInput& input, int channels, const Linearizer& linear, std::vector<Rgb>& texels) {
    const OIIO::ImageSpec& spec = input.spec();
    const OIIO::stride_t xstride = sizeof(Rgb), ystride = -OIIO::stride_t(sizeof(Rgb)) * spec.width;
    float* lastRow = &texels[size_t(spec.height - 1) * size_t(spec.width)].x;
    if (!input.read_image(0, 0, 0, channels, OIIO::TypeFloat, lastRow, xstride, ystride)) return false;
    for (Rgb& t : texels) t = channels == 1 ? Rgb(linear(t.x)) : Rgb(linear(t.x), linear(t.y), linear(t.z));
    return true;
}

// Wraps a texel index into [0, size) per the mode; false: the texel lies outside
// and the mode's constant (Zero/One) applies.
bool wrapIndex(int& i, int size, TextureDescription::Wrap mode) {
    if (i >= 0 && i < size) return true;
    switch (mode) {
    case TextureDescription::Wrap::Repeat: i = ((i % size) + size) % size; return true;
    case TextureDescription::Wrap::Mirror: {
        i = ((i % (2 * size)) + 2 * size) % (2 * size);
        if (i >= size) i = 2 * size - 1 - i;
        return true;
    }
    case TextureDescription::Wrap::Clamp: i = std::clamp(i, 0, size - 1); return true;
    case TextureDescription::Wrap::Zero:
    case TextureDescription::Wrap::One: return false;
    }
    return false;
}

// Reduces a texture coordinate by the wrap mode's period (or clamps it just
// outside [0, 1]) so that huge values neither overflow an int nor change the result.
float reduceCoordinate(float t, TextureDescription::Wrap mode) {
    switch (mode) {
    case TextureDescription::Wrap::Repeat: return t - std::floor(t);
    case TextureDescription::Wrap::Mirror: return t - 2.0f * std::floor(0.5f * t);
    default: return std::clamp(t, -1.0f, 2.0f);
    }
}

Rgb meanOf(const std::vector<Rgb>& texels) {
    double sum[3] = {0.0, 0.0, 0.0};
    for (const Rgb& t : texels)
        for (int c = 0; c < 3; ++c) sum[c] += t[c];
    const double n = double(texels.size());
    return texels.empty() ? Rgb(0.0f) : Rgb(float(sum[0] / n), float(sum[1] / n), float(sum[2] / n));
}

}  // namespace

Texture::Texture(int width, int height, std::vector<Rgb> texels, const TextureDescription& description)
    : width_(width), height_(height), texels_(std::move(texels)), description_(description) {
    if (width <= 0 || height <= 0 || texels_.size() != size_t(width) * size_t(height))
        throw std::invalid_argument("Texture: " + std::to_string(width) + " x " + std::to_string(height) +
                                    " needs that many texels, got " + std::to_string(texels_.size()));
    // Callers give row 0 at the top; store row 0 at the bottom.
    for (int y = 0; y < height / 2; ++y)
        std::swap_ranges(texels_.begin() + ptrdiff_t(y) * width, texels_.begin() + ptrdiff_t(y + 1) * width,
                         texels_.begin() + ptrdiff_t(height - 1 - y) * width);
    average_ = meanOf(texels_);
}

std::shared_ptr<const Texture> Texture::load(const TextureDescription& description) {
    const std::string file = description.filename.string();
    auto fail = [&](const std::string& reason) { return SceneError(description.where, "texture '" + file + "': " + reason); };

    std::error_code ec;
    if (!std::filesystem::exists(description.filename, ec)) throw fail("file not found");
    if (std::filesystem::is_directory(description.filename, ec)) throw fail("is a directory, not an image");

    // One decode at a time in the process: OpenImageIO 2.4's ImageInput::open is not
    // thread-safe for JPEG files (OpenImageIO issue #3756: a staircase load crashed
    // in it about once in twenty while another thread decoded a JPEG). Scene::build
    // loads its textures in turn; the lock also covers scenes built concurrently
    // (a worker's jobs). The library's own state is process-wide, so is this guard.
    static std::mutex decodeMutex;
    const std::lock_guard<std::mutex> decoding(decodeMutex);
    // Colour as stored, not multiplied by alpha (which is dropped).
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto input = OIIO::ImageInput::open(file, &config);
    if (!input) {
        const std::string message = OIIO::geterror();
        throw fail("cannot read the image: " + (message.empty() ? std::string("unknown format") : message));
    }
    // Decode on this thread: OIIO's shared thread pool, started by a parallel
    // conversion, is torn down by static destructors at exit, where OIIO 2.4 can
    // crash (seen once: a staircase render exited with SIGSEGV in
    // libOpenImageIO after writing its image; OIIO issue #3295).
    input->threads(1);
    const OIIO::ImageSpec spec = input->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.depth > 1 || spec.nchannels <= 0)
        throw fail("the image is empty (" + std::to_string(spec.width) + " x " + std::to_string(spec.height) + ", " +
                   std::to_string(spec.nchannels) + " channels)");
    if (spec.width > kMaxTextureSide || spec.height > kMaxTextureSide ||
        (long long)spec.width * spec.height > kMaxTextureTexels)
        throw fail("the image is too large (" + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                   "; at most " + std::to_string(kMaxTextureSide) + " per side and 2^28 texels)");
    if (spec.deep) throw fail("deep images are not supported");

    const Transfer transfer = transferFor(description, !spec.format.is_floating_point());

    // Grey (1 or 2 channels: grey + alpha) reads channel 0, colour channels 0-2;
    // alpha and further channels are dropped.
    const int width = spec.width, height = spec.height;
    const int channels = spec.nchannels < 3 ? 1 : 3;
    std::vector<Rgb> texels(size_t(width) * size_t(height));
    const auto stored = OIIO::TypeDesc::BASETYPE(spec.format.basetype);
    const Linearizer linear(transfer, spec.tile_width > 0 ? OIIO::TypeDesc::FLOAT : stored);
    bool ok = false;
    if (spec.tile_width > 0)
        ok = readWhole(*input, channels, linear, texels);
    else if (stored == OIIO::TypeDesc::UINT8)
        ok = readStrips<uint8_t>(*input, channels, OIIO::TypeUInt8, linear, texels);
    else if (stored == OIIO::TypeDesc::UINT16)
        ok = readStrips<uint16_t>(*input, channels, OIIO::TypeUInt16, linear, texels);
    else
        ok = readStrips<float>(*input, channels, OIIO::TypeFloat, linear, texels);
    if (!ok) {
        const std::string message = input->geterror();
        throw fail("cannot decode the image: " + (message.empty() ? std::string("unknown error") : message));
    }
    input->close();
    return std::make_shared<const Texture>(Texture(width, height, std::move(texels), description, BottomUp{}));
}

Texture::Texture(int width, int height, std::vector<Rgb> bottomUpTexels, const TextureDescription& description, BottomUp)
    : width_(width), height_(height), texels_(std::move(bottomUpTexels)), description_(description),
      average_(meanOf(texels_)) {}

Rgb Texture::eval(const Vec2& uv) const {
    const float u = uv.x * description_.uscale + description_.uoffset;
    const float v = uv.y * description_.vscale + description_.voffset;
    if (!std::isfinite(u) || !std::isfinite(v)) return Rgb(0.0f);

    // Continuous texel coordinates with texel centres at integers.
    const float x = reduceCoordinate(u, description_.wrapU) * float(width_) - 0.5f;
    const float y = reduceCoordinate(v, description_.wrapV) * float(height_) - 0.5f;
    const float x0f = std::floor(x), y0f = std::floor(y);
    const float fx = x - x0f, fy = y - y0f;
    const int x0 = int(x0f), y0 = int(y0f);

    auto texel = [&](int tx, int ty) -> Rgb {
        if (!wrapIndex(tx, width_, description_.wrapU))
            return Rgb(description_.wrapU == TextureDescription::Wrap::One ? 1.0f : 0.0f);
        if (!wrapIndex(ty, height_, description_.wrapV))
            return Rgb(description_.wrapV == TextureDescription::Wrap::One ? 1.0f : 0.0f);
        return texels_[size_t(ty) * size_t(width_) + size_t(tx)];
    };
    return texel(x0, y0) * ((1.0f - fx) * (1.0f - fy)) + texel(x0 + 1, y0) * (fx * (1.0f - fy)) +
           texel(x0, y0 + 1) * ((1.0f - fx) * fy) + texel(x0 + 1, y0 + 1) * (fx * fy);
}

}  // namespace vrl
