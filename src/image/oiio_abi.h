// The C interface between vrmlray and its OpenImageIO module (vrmlray_oiio.so, src/oiio/).
//
// Why a module: linking OpenImageIO pulls in about 260 shared libraries whose loading and static
// initialisers cost more than a small render at every process start (bench/README.md, "Figures
// behind the comments"). The binary therefore
// never links it; src/image/oiio_module.cpp dlopens the module the first time a format that is not
// handled natively (PNG, PPM) is read or written.
//
// Plain C types only, so that the two sides need not agree on anything but this file. Every
// function that can fail returns 0 (or NULL) and writes a NUL-terminated message into `error`
// (at most `error_size` bytes). Sample buffers are interleaved, rows from the top, in host order.
#pragma once
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

// Bumped whenever a signature or a meaning below changes; the loader refuses other versions.
#define VRMLRAY_OIIO_ABI_VERSION 2  // 2: float alpha is associated, integer alpha unassociated

enum VrOiioFormat { VR_OIIO_UINT8 = 0, VR_OIIO_UINT16 = 1, VR_OIIO_FLOAT = 2 };

// What an image file's header says.
typedef struct VrOiioSpec {
    int width;
    int height;
    int channels;
    int format;         // VrOiioFormat of the stored samples; VR_OIIO_FLOAT for anything else
    int alpha_channel;  // -1: none named
    int deep;           // nonzero: deep data (no flat pixels)
} VrOiioSpec;

typedef struct VrOiioInput VrOiioInput;  // an open file, header read

typedef int (*VrOiioAbiVersionFn)(void);
// Opens PATH and reads its header only. With `unassociated_alpha` colour comes back as stored,
// never multiplied or divided by alpha.
typedef VrOiioInput* (*VrOiioOpenFn)(const char* path, int unassociated_alpha, VrOiioSpec* spec,
                                     char* error, size_t error_size);
// Reads the first `channels` channels of every pixel as `format` into `samples`
// (width * height * channels values).
typedef int (*VrOiioReadFn)(VrOiioInput* input, int channels, int format, void* samples,
                            char* error, size_t error_size);
typedef void (*VrOiioCloseFn)(VrOiioInput* input);
// The channel count a file named PATH gets: 4 where the format has alpha, 3 otherwise; 0 when
// no writer knows PATH's extension.
typedef int (*VrOiioOutputChannelsFn)(const char* path);
// Writes samples (1 to 4 channels; with 2 or 4 the last is alpha) stored as `format`. The format's
// own settings (exr zip compression, jpeg quality 95, binary pnm, the Software tag, the sRGB
// colour-space tag when `srgb`) are chosen by the module from PATH's extension. Alpha is marked
// associated for VR_OIIO_FLOAT samples (premultiplied colour, EXR's convention) and unassociated
// for integer ones (straight colour). No timestamp is written: the same samples give the same
// bytes.
typedef int (*VrOiioWriteFn)(const char* path, int width, int height, int channels, int format,
                             const void* samples, int srgb, char* error, size_t error_size);

#ifdef __cplusplus
}
#endif
