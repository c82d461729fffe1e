// FilmCrop: the window of the film a render computes (Mitsuba's hdrfilm
// cropOffsetX, cropOffsetY, cropWidth, cropHeight; `vrl render --crop`), in film
// pixels from the film's top-left corner. The image is the window's size and
// its pixel (x, y) is film pixel (x0 + x, y0 + y), shaded with the same ray and
// the same random stream as in a render of the whole film (both are keyed by
// the film pixel, camera.h), so a crop equals that window of the full image
// bit for bit.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>

namespace vrl {

struct FilmCrop {
    int x0 = 0, y0 = 0;         // offset of the window's top-left pixel in the film
    int width = 0, height = 0;  // the window's (and the image's) size in pixels
    bool operator==(const FilmCrop&) const = default;

    // "x0,y0,width,height", as `--crop` takes it and vrl.crop records it.
    std::string toString() const {
        return std::to_string(x0) + "," + std::to_string(y0) + "," + std::to_string(width) + "," +
               std::to_string(height);
    }
};

// `crop` checked against a filmWidth x filmHeight film: std::invalid_argument
// naming the window, the film and the rule broken unless it is a non-empty
// window inside the film. Returns std::nullopt for the whole film (no crop).
inline std::optional<FilmCrop> checkFilmCrop(const FilmCrop& crop, int filmWidth, int filmHeight) {
    const std::string window = "the crop window " + crop.toString() + " (x,y,width,height)";
    const std::string film = "the " + std::to_string(filmWidth) + "x" + std::to_string(filmHeight) + " film";
    if (crop.width < 1 || crop.height < 1)
        throw std::invalid_argument(window + " is empty: its width and height must be at least 1");
    if (crop.x0 < 0 || crop.y0 < 0) throw std::invalid_argument(window + " has a negative offset");
    if (crop.x0 > filmWidth - crop.width || crop.y0 > filmHeight - crop.height)
        throw std::invalid_argument(window + " does not fit inside " + film + ": it needs x + width <= " +
                                    std::to_string(filmWidth) + " and y + height <= " + std::to_string(filmHeight) +
                                    ", got " + std::to_string(long(crop.x0) + crop.width) + " and " +
                                    std::to_string(long(crop.y0) + crop.height));
    if (crop == FilmCrop{0, 0, filmWidth, filmHeight}) return std::nullopt;
    return crop;
}

}  // namespace vrl
