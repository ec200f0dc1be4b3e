// Reading a texture image file (any format OpenImageIO reads) into float texels, bottom row first,
// as VRML texture coordinates expect (t = 0 at the bottom). Values are the file's, scaled to 0..1
// for integer formats, with no colour-space conversion (VRML browsers apply none).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace vr {

struct ImageData {
    int width = 0;
    int height = 0;
    int channels = 0;  // 1..4: intensity, intensity+alpha, RGB, RGBA (extra channels dropped)
    std::vector<float> texels;  // channels floats a texel, row 0 = bottom
};

// Returns false and sets `error` when the file cannot be read or is larger than `max_texels`
// texels.
bool read_image_file(const std::filesystem::path& path, ImageData& image, std::string& error,
                     size_t max_texels = size_t(1) << 27);

}  // namespace vr
