// Reading a texture image file into float texels, bottom row first, as VRML texture coordinates
// expect (t = 0 at the bottom). PNG is decoded natively; other formats (and interlaced PNG) go
// through the OpenImageIO module, loaded on first need. Values are the file's, integer codes
// divided to 0..1, with no colour-space conversion (VRML browsers apply none), and alpha is
// unassociated: colour is not multiplied by it.
#pragma once
#include <cstddef>
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

// 16384 x 16384: as float RGBA texels 4 GiB, beyond what a scene should ask for silently.
inline constexpr size_t kDefaultMaxTexturePixels = size_t(16384) * 16384;

// Returns false and sets `error` when the file cannot be read or has more than `max_texels`
// texels; the size is read from the header, before any texel memory is allocated, and the error
// then reads "the image is too large (W x H = N pixels; the limit is M)".
bool read_image_file(const std::filesystem::path& path, ImageData& image, std::string& error,
                     size_t max_texels = kDefaultMaxTexturePixels);

}  // namespace vr
