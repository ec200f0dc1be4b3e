// The C interface between vrmlray and its OpenEXR module (vrmlray_exr.so, src/exr/).
//
// Why a module: linking OpenEXR's C++ libraries costs milliseconds at every process start, and most
// runs write PNG; dlopened on the first EXR read or write it costs that once (figures:
// bench/README.md, "Figures behind the comments").
//
// Plain C types only. Functions that can fail return 0 and write a NUL-terminated message into
// `error` (at most `error_size` bytes). Samples are interleaved floats, rows from the top.
#pragma once
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define VRMLRAY_EXR_ABI_VERSION 1

// What vrmlray_exr_header found: the data window's size, and which channels vrmlray reads.
typedef struct VrExrSpec {
    int width;
    int height;
    int channels;  // 1 (Y), 2 (Y, A), 3 (R, G, B) or 4 (R, G, B, A); 0: other channels only
} VrExrSpec;

typedef int (*VrExrAbiVersionFn)(void);
// Reads PATH's header.
typedef int (*VrExrHeaderFn)(const char* path, VrExrSpec* spec, char* error, size_t error_size);
// Reads the channels vrmlray_exr_header named (spec->channels of them, in that order) as 32-bit
// floats into `samples` (width * height * channels values).
typedef int (*VrExrReadFn)(const char* path, const VrExrSpec* spec, float* samples, char* error,
                           size_t error_size);
// Writes 3 (R, G, B) or 4 (R, G, B, A; colour premultiplied, EXR's convention) channels of 32-bit
// float, ZIP compressed, with no time or date in the header: the same samples give the same bytes.
typedef int (*VrExrWriteFn)(const char* path, int width, int height, int channels,
                            const float* samples, char* error, size_t error_size);

#ifdef __cplusplus
}
#endif
