// PNG reading and writing through libpng, so that rendering to PNG, comparing PNGs and PNG
// textures never load the OpenImageIO module (see oiio_abi.h for why that matters).
//
// Reading returns what OpenImageIO (libpng underneath) returns, so that switching readers changes
// no value: every colour type, bit depth and interlacing of the specification; 1-, 2- and 4-bit
// grey expanded to 8-bit codes (v * 255 / (2^d - 1)); palette images expanded to RGB; a tRNS chunk
// becomes an alpha channel (grey -> grey + alpha, RGB and palette -> RGBA); 16-bit stays 16-bit.
// Sample code k is returned as the float nearest k/255 or k/65535 (divided, not multiplied by a
// reciprocal). No transfer curve is undone (gAMA, sRGB and iCCP are not applied) and alpha is never
// multiplied in.
//
// Safety: the pixel count is checked against the caller's limit from the header, before any image
// memory exists; damaged files (bad CRC in a critical chunk, bad compressed data, truncation) are
// errors with libpng's message, never a crash.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace vr {

struct PngPixels {
    int width = 0;
    int height = 0;
    int channels = 0;            // 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA
    int bit_depth = 0;           // of the returned codes: 8 or 16
    std::vector<float> samples;  // channels floats a pixel, top row first
};

enum class PngStatus {
    kOk,
    kNotPng,  // no PNG signature: some other format
    kError,   // `error` says why
};

// Decodes a whole PNG file held in memory. More than `max_pixels` pixels is an error, found from
// the header before any image memory is allocated.
PngStatus decode_png(const uint8_t* data, size_t size, size_t max_pixels, PngPixels& pixels,
                     std::string& error);

// Reads PATH as a stream: a too large image is refused from its header, before the rest of the
// file is read. A missing or unreadable file is kError.
PngStatus read_png(const std::string& path, size_t max_pixels, PngPixels& pixels,
                   std::string& error);

// Writes `channels` (1..4, alpha last for 2 and 4) samples a pixel, rows from the top, as an 8- or
// 16-bit PNG: `samples` points at uint8_t or uint16_t values accordingly. Filtered per row by
// libpng's heuristic (smallest sum of absolute filtered bytes) and deflated by zlib at level 6 with
// both its filtered and its default strategy (on two threads), keeping the smaller file. With
// `srgb` the file carries the sRGB, gAMA and cHRM chunks OpenImageIO writes for an sRGB image; it
// always carries a tEXt "Software" = "vrmlray". On failure the partial file is removed.
bool write_png(const std::string& path, int width, int height, int channels, int bit_depth,
               const void* samples, bool srgb, std::string& error);

}  // namespace vr
