// OpenEXR reading and writing through the OpenEXR module (vrmlray_exr.so, image/exr_abi.h),
// dlopened on first use. EXR is the ground-truth format: it no longer needs the OpenImageIO module.
//
// Written: R, G, B (and A with alpha, colour premultiplied: EXR's convention) as 32-bit float, ZIP
// compression, a "Software" = "vrmlray" attribute and no date: what the OpenImageIO module wrote.
// Read: R, G, B with A when present, or Y with A when present, as stored (no alpha division); other
// channel sets are kOtherChannels, left to the OpenImageIO module.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace vr {

struct ExrPixels {
    int width = 0;
    int height = 0;
    int channels = 0;            // 1 Y, 2 Y + A, 3 RGB, 4 RGBA
    std::vector<float> samples;  // channels floats a pixel, top row first
};

enum class ExrStatus { kOk, kNotExr, kOtherChannels, kError };

// Reads PATH; more than `max_pixels` pixels is an error, found from the header before any pixel
// memory exists. An EXR file when the module cannot be loaded is kError ("the OpenEXR module PATH
// could not be loaded: WHY").
ExrStatus read_exr(const std::string& path, size_t max_pixels, ExrPixels& pixels,
                   std::string& error);

// Loads the module (once per process): false, with the reason, when it cannot be loaded.
// check_output asks before rendering, so that a missing module fails at once, not after the render.
bool exr_available(std::string& error);

// 3 or 4 channels a pixel, rows from the top. On failure the partial file is removed.
bool write_exr(const std::string& path, int width, int height, int channels, const float* samples,
               std::string& error);

}  // namespace vr
