// A float RGBA image in memory, and reading/writing it: PNG and PPM natively, other formats through
// OpenImageIO, loaded as a module on first need (image/oiio_module.h).
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace vr {

struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> rgba;  // 4 floats a pixel, rows from the top, linear values

    Image() = default;
    Image(int w, int h) : width(w), height(h), rgba(size_t(w) * size_t(h) * 4, 0.0f) {}
    float* pixel(int x, int y) { return rgba.data() + (size_t(y) * size_t(width) + size_t(x)) * 4; }
    const float* pixel(int x, int y) const {
        return rgba.data() + (size_t(y) * size_t(width) + size_t(x)) * 4;
    }
};

// Images read for comparison larger than this are refused before any pixel memory exists
// (16384 x 16384; 4 GiB as float RGBA).
inline constexpr size_t kMaxImagePixels = size_t(16384) * 16384;

// Writes by OUT's extension (png, exr, hdr, tif, jpg, ppm, ...). Integer formats get values clamped
// to [0,1], or sRGB-encoded when `srgb` is set; float formats get linear unclamped values. Alpha is
// written where the format has it. Returns false and sets `error` on failure (naming the file;
// "cannot write FORMAT 'FILE': the OpenImageIO module PATH could not be loaded: WHY" when the
// format needs the module and it cannot be loaded).
bool write_image(const std::string& path, const Image& image, bool srgb, std::string& error);
// Reads any format OpenImageIO reads into linear-as-stored RGBA floats (missing alpha = 1); PNG
// without the module.
bool read_image(const std::string& path, Image& image, std::string& error);

}  // namespace vr
