// Reading image files into float samples: textures for the scene build and flatten, and the images
// vrmlray compare reads (image.h). The format is recognised by the file's signature, not its name:
// PNG through libpng (png.h), JPEG through libjpeg-turbo (jpeg.h), EXR through the OpenEXR module
// (exr.h); every other format, and JPEG or EXR files those cannot represent (CMYK, EXR layers),
// through the OpenImageIO module, loaded on first need. Values are the file's, integer codes
// divided to 0..1, with no colour-space conversion (VRML browsers apply none), and alpha as stored:
// colour is not multiplied or divided by it.
#pragma once
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace vr {

// A file's samples, top row first.
struct FilePixels {
    int width = 0;
    int height = 0;
    int channels = 0;            // as kept (at most the caller's max_channels)
    int alpha_channel = -1;      // as the file names it (may be >= channels), -1 none
    std::vector<float> samples;  // channels floats a pixel
};

// Reads PATH, keeping the first `max_channels` channels. More than `max_pixels` pixels is refused
// from the header, before any pixel memory exists. On failure `error` is the bare reason (the
// caller names the file) and `module_format` names the format ("EXR", "TIF", ...) when
// the failure was loading a module that format needs, else it is empty.
bool read_file_pixels(const std::string& path, int max_channels, size_t max_pixels,
                      FilePixels& pixels, std::string& error, std::string& module_format);

// A texture: float texels, bottom row first, as VRML texture coordinates expect (t = 0 at the
// bottom).
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
