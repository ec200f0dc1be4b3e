#include "scene/image_file.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstring>

namespace vr {

bool read_image_file(const std::filesystem::path& path, ImageData& image, std::string& error,
                     size_t max_texels) {
    auto input = OIIO::ImageInput::open(path.string());
    if (!input) {
        error = OIIO::geterror();
        if (error.empty()) error = "cannot open the image";
        return false;
    }
    const OIIO::ImageSpec& spec = input->spec();
    const int width = spec.width, height = spec.height;
    const int file_channels = spec.nchannels;
    if (width <= 0 || height <= 0 || file_channels <= 0) {
        error = "the image is empty";
        return false;
    }
    if (size_t(width) * size_t(height) > max_texels) {
        error = "the image is too large (" + std::to_string(width) + " x " +
                std::to_string(height) + ")";
        return false;
    }
    const int channels = std::min(file_channels, 4);
    std::vector<float> top_first(size_t(width) * height * channels);
    if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, top_first.data())) {
        error = input->geterror();
        if (error.empty()) error = "cannot read the image";
        return false;
    }
    input->close();
    image.width = width;
    image.height = height;
    image.channels = channels;
    image.texels.resize(top_first.size());
    const size_t row = size_t(width) * channels;
    for (int y = 0; y < height; ++y)
        std::memcpy(image.texels.data() + size_t(height - 1 - y) * row,
                    top_first.data() + size_t(y) * row, row * sizeof(float));
    return true;
}

}  // namespace vr
