// Texture: an RGB image looked up by surface uv (Mitsuba's `bitmap` texture),
// stored as linear float RGB after decoding (OpenImageIO) and undoing the
// file's gamma. Lookups are bilinear with the description's wrap modes and
// uv scale/offset; v = 0 is the bottom row of the image (Mitsuba/OBJ convention).
// Immutable after loading: safe to share between threads and BSDFs.
#pragma once

#include "render/core/geometry.h"
#include "render/core/rgb.h"
#include "render/description/scene_description.h"

#include <memory>
#include <vector>

namespace vrl {

class Texture {
public:
    // Loads and linearises the image. Throws SceneError (naming the file and the
    // texture's location) for a missing, unreadable or empty image.
    static std::shared_ptr<const Texture> load(const TextureDescription& description);
    // A width x height texture from linear RGB texels, row 0 at the top (tests).
    Texture(int width, int height, std::vector<Rgb> texels, const TextureDescription& description = {});

    Rgb eval(const Vec2& uv) const;
    // Mean texel value (for light-tree and sampling decisions that need one colour).
    const Rgb& average() const { return average_; }
    int width() const { return width_; }
    int height() const { return height_; }

private:
    struct BottomUp {};  // tag: texels already stored with row 0 at the bottom
    Texture(int width, int height, std::vector<Rgb> bottomUpTexels, const TextureDescription& description, BottomUp);

    int width_ = 0, height_ = 0;
    std::vector<Rgb> texels_;  // row-major, row 0 = bottom row of the image (v = 0)
    TextureDescription description_;
    Rgb average_{0.0f};
};

// A colour parameter at run time: value * texture(uv), or value alone.
struct TexturedColor {
    Rgb value{0.5f};
    std::shared_ptr<const Texture> texture;

    Rgb eval(const Vec2& uv) const { return texture ? value * texture->eval(uv) : value; }
    bool isConstant() const { return !texture; }
};

}  // namespace vrl
