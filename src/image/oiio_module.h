// The OpenImageIO module (vrmlray_oiio.so), loaded with dlopen the first time an image format
// that is not handled natively is read or written (see oiio_abi.h for why).
//
// Where it is looked for: image/module_path.h.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "image/oiio_abi.h"

namespace vr {

struct OiioModule {
    std::string path;  // the file that was loaded
    void* handle = nullptr;
    VrOiioOpenFn open = nullptr;
    VrOiioReadFn read = nullptr;
    VrOiioCloseFn close = nullptr;
    VrOiioOutputChannelsFn output_channels = nullptr;
    VrOiioWriteFn write = nullptr;
};

// The paths tried, in order.
std::vector<std::string> oiio_module_candidates();

// Loads the first candidate that opens and has the expected interface. On failure `error` reads
// "the OpenImageIO module PATH could not be loaded: WHY" (PATH the first candidate that exists,
// WHY dlerror's text), naming the other candidates tried.
bool load_oiio_module(const std::vector<std::string>& candidates, OiioModule& module,
                      std::string& error);

// The process's module: loaded on the first call (thread-safe), never unloaded. Null, with the
// reason in `error`, when it cannot be loaded (every later call gives the same answer).
const OiioModule* oiio_module(std::string& error);

// An image read through the module.
struct OiioPixels {
    int width = 0;
    int height = 0;
    int channels = 0;            // as kept (at most the caller's max_channels)
    int alpha_channel = -1;      // as the file names it (may be >= channels), -1 none
    std::vector<float> samples;  // channels floats a pixel, top row first
};

// Reads PATH through OpenImageIO: the header first (more than `max_pixels` pixels is refused
// before any pixel memory exists), then the first min(channels, max_channels) channels. 8- and
// 16-bit files are read as integers and divided here, so that code k becomes the float nearest
// k/255 or k/65535 (OpenImageIO's own conversion multiplies by a rounded reciprocal). Alpha stays
// unassociated. `error` is the bare reason (the caller names the file).
bool oiio_read_pixels(const std::string& path, int max_channels, size_t max_pixels,
                      OiioPixels& pixels, std::string& error);

// Samples are uint8_t, uint16_t or float by `format` (VrOiioFormat); 1 to 4 channels, alpha last
// with 2 or 4.
bool oiio_write_pixels(const std::string& path, int width, int height, int channels, int format,
                       const void* samples, bool srgb, std::string& error);

// The channel count PATH's format stores (4 with alpha, 3 without), 0 when no writer knows its
// extension, -1 (with `error` set) when the module cannot be loaded.
int oiio_output_channels(const std::string& path, std::string& error);

}  // namespace vr
