// A float RGBA image in memory (colour premultiplied by alpha when rendered with --alpha), and
// reading/writing it: PNG (libpng), PPM and EXR (the OpenEXR module, image/exr.h) without
// OpenImageIO, other formats through OpenImageIO, loaded as a module on first need
// (image/oiio_module.h).
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "core/huge_pages.h"
#include "core/no_fill.h"

namespace vr {

struct Image {
    int width = 0;
    int height = 0;
    std::vector<float, NoFillAllocator<float>>
        rgba;  // 4 floats a pixel, rows from the top, linear values
    // What read_image found in the file: its channel count (0: the image was made in memory) and
    // whether one was alpha (else rgba[3] is a filler 1). compare uses them: alpha is compared only
    // where both images have one, and different channel counts fail.
    int file_channels = 0;
    bool has_alpha = true;

    Image() = default;
    // All pixels 0.
    Image(int w, int h) : width(w), height(h) {
        resize_huge(rgba, size_t(w) * size_t(h) * 4);
        std::fill(rgba.begin(), rgba.end(), 0.0f);
    }
    // Pixels unset, for a producer that writes every one (the tracer): a 1920x1080 image is 33 MB,
    // and zero-filling it first would fault all its pages in on one thread before the first ray;
    // unfilled, each tracing thread faults in the pages of the tiles it writes.
    static Image unfilled(int w, int h) {
        Image image;
        image.width = w;
        image.height = h;
        resize_huge(image.rgba, size_t(w) * size_t(h) * 4);
        return image;
    }
    float* pixel(int x, int y) { return rgba.data() + (size_t(y) * size_t(width) + size_t(x)) * 4; }
    const float* pixel(int x, int y) const {
        return rgba.data() + (size_t(y) * size_t(width) + size_t(x)) * 4;
    }
};

// 8-bit samples as PNG and PPM files store them: `channels` (3: RGB, 4: RGBA) a pixel, rows from
// the top. What vrmlray render keeps for those formats instead of an Image: a quarter of the
// memory.
struct Image8 {
    int width = 0;
    int height = 0;
    int channels = 4;
    std::vector<uint8_t, NoFillAllocator<uint8_t>> samples;
};

// Images read for comparison larger than this are refused before any pixel memory exists
// (16384 x 16384; 4 GiB as float RGBA).
inline constexpr size_t kMaxImagePixels = size_t(16384) * 16384;

struct WriteOptions {
    bool srgb = false;  // integer formats: sRGB-encode the colour (never alpha)
    // Write the alpha channel; the Image's colour is then premultiplied by it (what the tracer
    // gives with RenderOptions::alpha). Float formats (EXR) store it so, marked associated; integer
    // formats (PNG, TIFF, ...) store colour / alpha (straight, 0 where alpha is 0), marked
    // unassociated.
    bool alpha = false;
};

// Writes by OUT's extension (png, exr, hdr, tif, jpg, ppm, ...). Integer formats get values clamped
// to [0,1], or sRGB-encoded when `srgb` is set; float formats get linear unclamped values. RGB only
// unless options.alpha (an error for a format without alpha). Returns false and sets `error` on
// failure (naming the file; "cannot write FORMAT 'FILE': the OpenImageIO module PATH could not be
// loaded: WHY" when the format needs the module and it cannot be loaded).
bool write_image(const std::string& path, const Image& image, const WriteOptions& options,
                 std::string& error);
// RGB, no alpha.
inline bool write_image(const std::string& path, const Image& image, bool srgb,
                        std::string& error) {
    return write_image(path, image, WriteOptions{srgb, false}, error);
}

// Whether OUT can be written, asked before any rendering (docs/manual.md, render): its extension
// names a format a writer knows (png, ppm and exr without OpenImageIO; others through its module,
// loaded here), that format holds alpha if `alpha`, its folder exists and is writable, and OUT is
// not a folder or a read-only file. Nothing is created.
enum class OutputCheck { kOk, kNotWritable, kNoAlpha };
OutputCheck check_output(const std::string& path, bool alpha, std::string& error);

// The channels an 8-bit file of OUT's format holds when written natively (png: 3, with alpha 4;
// ppm: 3), else 0 (the format needs write_image).
int native_8bit_channels(const std::string& path, bool alpha = false);
// Encodes `count` RGBA pixels as write_image does for an 8-bit file: `channels` bytes a pixel (3:
// RGB; 4: colour / alpha and alpha, the colour being premultiplied in `rgba`), clamped to [0,1],
// colour sRGB-encoded when `srgb`, NaN as 0.
void encode_8bit(const float* rgba, size_t count, int channels, bool srgb, uint8_t* out);
// encode_8bit of a tile of RGBA pixels (rows of x1 - x0, top to bottom) into `image` at [x0, x1) x
// [y0, y1). A tile of one value (most of the image of a small scene, where the tracer fills a
// background tile from one ray) is encoded once and copied: returns true then.
bool encode_tile_8bit(const float* rgba, int x0, int y0, int x1, int y1, bool srgb, Image8& image);
// Writes `image` (3 or, for png, 4 channels: native_8bit_channels(path, alpha)) byte for byte as
// write_image writes the Image it was encoded from.
bool write_image8(const std::string& path, const Image8& image, bool srgb, std::string& error);
// Reads any format OpenImageIO reads into linear-as-stored RGBA floats (missing alpha = 1); PNG
// without the module.
bool read_image(const std::string& path, Image& image, std::string& error);

}  // namespace vr
