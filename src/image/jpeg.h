// JPEG reading through libjpeg-turbo (libjpeg's API), so that JPEG textures do not load the
// OpenImageIO module. The values are those OpenImageIO (libjpeg underneath, default settings)
// returns: 8-bit codes k as the float nearest k/255, grey as one channel, colour as RGB.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace vr {

struct JpegPixels {
    int width = 0;
    int height = 0;
    int channels = 0;            // 1 grey, 3 RGB
    std::vector<float> samples;  // channels floats a pixel, top row first
};

enum class JpegStatus {
    kOk,
    kNotJpeg,      // no JPEG signature (FF D8 FF): some other format
    kUnsupported,  // a JPEG whose colour space (CMYK, YCCK) is left to the OpenImageIO module
    kError,        // `error` says why
};

// Reads PATH; more than `max_pixels` pixels is an error, found from the header before any pixel
// memory exists.
JpegStatus read_jpeg(const std::string& path, size_t max_pixels, JpegPixels& pixels,
                     std::string& error);

}  // namespace vr
