#include "image/texture_file.h"

#include <algorithm>
#include <cctype>
#include <cstddef>

#include "image/exr.h"
#include "image/jpeg.h"
#include "image/oiio_module.h"
#include "image/png.h"

namespace vr {
namespace {

// Keeps the first `max_channels` of `channels` interleaved channels.
void keep_channels(std::vector<float>& samples, int channels, int max_channels) {
    if (channels <= max_channels) return;
    const size_t npix = samples.size() / size_t(channels);
    for (size_t p = 0; p < npix; ++p)
        for (int c = 0; c < max_channels; ++c)
            samples[p * size_t(max_channels) + size_t(c)] =
                samples[p * size_t(channels) + size_t(c)];
    samples.resize(npix * size_t(max_channels));
}

template <class Native>
void take(Native& native, int alpha, int max_channels, FilePixels& pixels) {
    pixels.width = native.width;
    pixels.height = native.height;
    pixels.channels = std::min(native.channels, max_channels);
    pixels.alpha_channel = alpha;
    keep_channels(native.samples, native.channels, max_channels);
    pixels.samples = std::move(native.samples);
}

// "JPG" for "x.jpg": how a message names the format that needed the module.
std::string extension_name(const std::string& path) {
    std::string format = std::filesystem::path(path).extension().string();
    if (!format.empty() && format[0] == '.') format.erase(0, 1);
    for (char& c : format) c = char(std::toupper(static_cast<unsigned char>(c)));
    return format.empty() ? std::string("the image") : format;
}

}  // namespace

bool read_file_pixels(const std::string& path, int max_channels, size_t max_pixels,
                      FilePixels& pixels, std::string& error, std::string& module_format) {
    module_format.clear();
    PngPixels png;
    const PngStatus png_status = read_png(path, max_pixels, png, error);
    if (png_status == PngStatus::kError) return false;
    if (png_status == PngStatus::kOk) {
        take(png, png.channels == 2 ? 1 : png.channels == 4 ? 3 : -1, max_channels, pixels);
        return true;
    }
    JpegPixels jpeg;
    const JpegStatus jpeg_status = read_jpeg(path, max_pixels, jpeg, error);
    if (jpeg_status == JpegStatus::kError) return false;
    if (jpeg_status == JpegStatus::kOk) {
        take(jpeg, -1, max_channels, pixels);
        return true;
    }
    ExrPixels exr;
    const ExrStatus exr_status = read_exr(path, max_pixels, exr, error);
    if (exr_status == ExrStatus::kError) {
        if (error.rfind("the OpenEXR module", 0) == 0) module_format = "EXR";
        return false;
    }
    if (exr_status == ExrStatus::kOk) {
        take(exr, exr.channels == 2 ? 1 : exr.channels == 4 ? 3 : -1, max_channels, pixels);
        return true;
    }
    if (!oiio_module(error)) {
        module_format = exr_status == ExrStatus::kOtherChannels   ? std::string("EXR")
                        : jpeg_status == JpegStatus::kUnsupported ? std::string("CMYK JPEG")
                                                                  : extension_name(path);
        return false;
    }
    OiioPixels oiio;
    if (!oiio_read_pixels(path, max_channels, max_pixels, oiio, error)) return false;
    pixels.width = oiio.width;
    pixels.height = oiio.height;
    pixels.channels = oiio.channels;
    pixels.alpha_channel = oiio.alpha_channel;
    pixels.samples = std::move(oiio.samples);
    return true;
}

bool read_image_file(const std::filesystem::path& path, ImageData& image, std::string& error,
                     size_t max_texels) {
    FilePixels pixels;
    std::string format;
    if (!read_file_pixels(path.string(), 4, max_texels, pixels, error, format)) {
        if (!format.empty()) error = "cannot read " + format + ": " + error;
        return false;
    }
    image.width = pixels.width;
    image.height = pixels.height;
    image.channels = pixels.channels;
    // Flipped in place: a large texture is not held twice.
    std::vector<float>& top_first = pixels.samples;
    const size_t row = size_t(pixels.width) * size_t(pixels.channels);
    for (int y = 0; y < pixels.height / 2; ++y)
        std::swap_ranges(top_first.begin() + ptrdiff_t(size_t(y) * row),
                         top_first.begin() + ptrdiff_t(size_t(y + 1) * row),
                         top_first.begin() + ptrdiff_t(size_t(pixels.height - 1 - y) * row));
    image.texels = std::move(top_first);
    return true;
}

}  // namespace vr
