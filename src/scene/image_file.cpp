#include "scene/image_file.h"

#include <algorithm>
#include <cctype>
#include <cstddef>

#include "image/oiio_module.h"
#include "image/png.h"

namespace vr {

bool read_image_file(const std::filesystem::path& path, ImageData& image, std::string& error,
                     size_t max_texels) {
    int width = 0, height = 0, channels = 0;
    std::vector<float> top_first;
    PngPixels png;
    const PngStatus status = read_png(path.string(), max_texels, png, error);
    if (status == PngStatus::kError) return false;
    if (status == PngStatus::kOk) {
        width = png.width, height = png.height, channels = png.channels;
        top_first = std::move(png.samples);
    } else {
        std::string why;
        if (!oiio_module(why)) {
            std::string format = path.extension().string();
            if (!format.empty() && format[0] == '.') format.erase(0, 1);
            for (char& c : format) c = char(std::toupper(static_cast<unsigned char>(c)));
            if (status == PngStatus::kInterlaced) format = "interlaced PNG";
            error =
                "cannot read " + (format.empty() ? std::string("the image") : format) + ": " + why;
            return false;
        }
        OiioPixels pixels;
        if (!oiio_read_pixels(path.string(), 4, max_texels, pixels, error)) return false;
        width = pixels.width, height = pixels.height, channels = pixels.channels;
        top_first = std::move(pixels.samples);
    }
    image.width = width;
    image.height = height;
    image.channels = channels;
    // Flipped in place: a large texture is not held twice.
    const size_t row = size_t(width) * channels;
    for (int y = 0; y < height / 2; ++y)
        std::swap_ranges(top_first.begin() + ptrdiff_t(size_t(y) * row),
                         top_first.begin() + ptrdiff_t(size_t(y + 1) * row),
                         top_first.begin() + ptrdiff_t(size_t(height - 1 - y) * row));
    image.texels = std::move(top_first);
    return true;
}

}  // namespace vr
