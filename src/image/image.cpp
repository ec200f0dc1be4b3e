// Reading and writing float RGBA images: PNG (libpng, png.h), binary PPM and EXR (the OpenEXR
// module, exr.h) without OpenImageIO, every other format through the OpenImageIO module
// (oiio_module.h), which is loaded only then. Reading goes through read_file_pixels
// (texture_file.h).
//
// What reaches a file (docs/manual.md, render):
//   - The extension picks the format and the stored sample type:
//       png, ppm/pnm, jpg/jpeg, bmp, tga, ...  8-bit unsigned integers
//       tif/tiff                               16-bit unsigned integers
//       exr                                    32-bit float (zip, lossless)
//       hdr/rgbe, pfm                          float (RGBE / raw float)
//   - Integer formats store the value clamped to [0,1] as is (VRML browsers apply no transfer
//     curve), or sRGB-encoded by the exact piecewise IEC 61966-2-1 curve when `srgb` is set, then
//     quantised by round to nearest: code = floor(v * max + 0.5), max = 255 or 65535, computed in
//     double. Alpha is never sRGB-encoded.
//   - Float formats store linear, unclamped values (`srgb` is ignored). RGBE cannot hold negative
//     numbers, so hdr clamps them to 0.
//   - RGB by default, whatever the format. With WriteOptions::alpha, RGBA (an error for a format
//     without alpha: jpg, ppm, hdr, ...): the Image's colour is premultiplied; float formats (exr)
//     store it so, marked associated (EXR's convention); integer formats store colour / alpha
//     (straight; 0 where alpha is 0), marked unassociated (PNG's and TIFF's convention).
//   - No NaN or infinity is ever written: NaN becomes 0, +-infinity the largest finite float of
//     its sign (then clamped like any other value).
//   - Files are read back as stored: alpha is never multiplied or divided in by OpenImageIO.
//   - No timestamps: the same pixels give the same bytes.
//   - The native writers store what OpenImageIO stored before them: PNG 8-bit RGB or RGBA (tEXt
//     Software, and the sRGB/gAMA/cHRM chunks with `srgb`), PPM "P6 W H 255" with 8-bit RGB.
// Reading returns the stored values as floats (8/16-bit code k as the float nearest k/255 or
// k/65535), no transfer curve undone. PNG, JPEG and EXR files are recognised by their signature,
// not their name; other formats go through the OpenImageIO module.
#include "image/image.h"

#include <unistd.h>
#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <type_traits>

#include "image/exr.h"
#include "image/oiio_module.h"
#include "image/output_file.h"
#include "image/png.h"
#include "image/texture_file.h"

namespace vr {
namespace {

enum class SampleKind { kUint8, kUint16, kFloat };

struct FormatChoice {
    SampleKind kind = SampleKind::kUint8;
    bool clamp_negative = false;  // float formats that cannot hold negative values (RGBE)
};

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    if (!ext.empty() && ext[0] == '.') ext.erase(0, 1);
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

FormatChoice choose_format(const std::string& ext) {
    FormatChoice f;
    if (ext == "exr" || ext == "sxr" || ext == "mxr" || ext == "pfm") {
        f.kind = SampleKind::kFloat;
    } else if (ext == "hdr" || ext == "rgbe") {
        f.kind = SampleKind::kFloat;
        f.clamp_negative = true;
    } else if (ext == "tif" || ext == "tiff") {
        f.kind = SampleKind::kUint16;
    }
    return f;
}

// NaN -> 0, +-inf -> +-largest finite float.
float finite_or_zero(float v) {
    if (std::isnan(v)) return 0.0f;
    if (std::isinf(v))
        return v > 0 ? std::numeric_limits<float>::max() : std::numeric_limits<float>::lowest();
    return v;
}

// The exact piecewise sRGB encoding of a linear value in [0,1].
double srgb_encode(double v) {
    if (v <= 0.0031308) return 12.92 * v;
    return 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

// Clamps to [0,1] (after optional sRGB encoding) and rounds to nearest integer code in [0,
// max_code].
uint32_t quantize(float value, bool srgb, double max_code) {
    double v = std::clamp(double(finite_or_zero(value)), 0.0, 1.0);
    if (srgb) v = std::clamp(srgb_encode(v), 0.0, 1.0);
    return uint32_t(std::floor(v * max_code + 0.5));
}

// quantize(value, true, 255) without a pow per sample: code i + 1 starts at the smallest float
// whose code is at least i + 1, found once by bisection over the bit patterns of [0, 1] (ordered
// like their values) with quantize itself, so the two agree on every float. A sample's code is then
// its bucket's first code (the bucket: the top 16 bits of the float, 2^-7 of its value wide),
// stepped past the code starts in the bucket: none or one, as a code spans at least 0.9% of its
// linear value.
struct Srgb8 {
    static constexpr uint32_t kOneBits = 0x3F800000u;  // 1.0f
    float first[255];                                  // first[i]: where code i + 1 starts
    uint8_t bucket[(kOneBits >> 16) + 1];              // code of the smallest float of each bucket
    Srgb8() {
        for (uint32_t code = 1; code <= 255; ++code) {
            uint32_t lo = 0, hi = 0x3F800000u;  // 0.0f, 1.0f: quantize(1) = 255
            while (lo < hi) {
                const uint32_t mid = lo + (hi - lo) / 2;
                float f;
                std::memcpy(&f, &mid, sizeof f);
                if (quantize(f, true, 255.0) >= code)
                    hi = mid;
                else
                    lo = mid + 1;
            }
            std::memcpy(&first[code - 1], &lo, sizeof(float));
        }
        for (uint32_t b = 0; b <= (kOneBits >> 16); ++b) {
            const uint32_t bits = b << 16;
            float f;
            std::memcpy(&f, &bits, sizeof f);
            // Codes are monotone in the value: count the starts at or below it.
            bucket[b] = uint8_t(std::upper_bound(first, first + 255, f) - first);
        }
    }
    uint8_t operator()(float value) const {
        uint32_t bits;
        std::memcpy(&bits, &value, sizeof bits);
        if (bits >= kOneBits) {
            // [1, +inf] (+inf counts as the largest float) is 255; negatives (the sign bit), -0 and
            // NaN are 0.
            return bits <= 0x7F800000u ? 255 : 0;
        }
        uint32_t code = bucket[bits >> 16];
        while (code < 255 && value >= first[code]) ++code;
        return uint8_t(code);
    }
};

// "EXR" for "exr": how a message names the format that needed the module.
std::string format_name(const std::string& ext) {
    std::string name = ext;
    for (char& c : name) c = char(std::toupper(static_cast<unsigned char>(c)));
    return name.empty() ? std::string("the image") : name;
}

// quantize(x, false, 255) for the 8-bit encode of every tile: NaN and everything below 0 give 0,
// everything from 1 up (+inf too) 255, and the rounding is quantize's floor(v * 255 + 0.5),
// truncation being floor for v >= 0.
inline uint8_t linear8(float x) {
    const double v = x > 0.0f ? (x < 1.0f ? double(x) : 1.0) : 0.0;
    return uint8_t(v * 255.0 + 0.5);
}

#if defined(__AVX2__)
// linear8 of every sample of `count` RGBA pixels, the first `nchannels` (3 or 4) of each stored.
// A block's samples are converted 8 at a time over contiguous floats, then the kept channels
// packed: a pass that skips every fourth sample does not vectorise. max(x, 0) is 0 for NaN (maxps
// returns its second operand), and v * 255 is exact in double, so a fused multiply-add rounds as
// the scalar does.
template <typename T>
void linear8_avx2(const float* in, size_t count, int nchannels, T* out) {
    constexpr size_t kBlock = 64;
    uint8_t all[kBlock * 4];
    const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    const __m256d scale = _mm256_set1_pd(255.0), half = _mm256_set1_pd(0.5);
    for (size_t first = 0; first < count; first += kBlock) {
        const size_t n = std::min(kBlock, count - first);
        const float* block = in + first * 4;
        size_t i = 0;
        for (; i + 8 <= n * 4; i += 8) {
            const __m256 v = _mm256_min_ps(_mm256_max_ps(_mm256_loadu_ps(block + i), zero), one);
            const __m256d lo = _mm256_add_pd(
                _mm256_mul_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(v)), scale), half);
            const __m256d hi = _mm256_add_pd(
                _mm256_mul_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(v, 1)), scale), half);
            const __m128i words =
                _mm_packus_epi32(_mm256_cvttpd_epi32(lo), _mm256_cvttpd_epi32(hi));
            _mm_storel_epi64(reinterpret_cast<__m128i*>(all + i), _mm_packus_epi16(words, words));
        }
        for (; i < n * 4; ++i) all[i] = linear8(block[i]);
        T* to = out + first * size_t(nchannels);
        if (nchannels == 4) {
            std::copy_n(all, n * 4, to);
            continue;
        }
        size_t p = 0;
        if constexpr (std::is_same_v<T, uint8_t>) {
            // RGBA -> RGB four pixels a shuffle. Each 16-byte store ends in 4 bytes that the next
            // store (or the loop after) overwrites, so it stops while 2 pixels remain.
            const __m128i pick =
                _mm_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1);
            for (; p + 6 <= n; p += 4)
                _mm_storeu_si128(
                    reinterpret_cast<__m128i*>(to + p * 3),
                    _mm_shuffle_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(all + p * 4)),
                                     pick));
        }
        for (; p < n; ++p)
            for (int c = 0; c < 3; ++c) to[p * 3 + c] = T(all[p * 4 + c]);
    }
}
#endif

// Converts `count` RGBA pixels at `in` to the interleaved samples stored in the file (nchannels per
// pixel) at `out`, colour as given.
template <typename T>
void to_stored_samples(const float* in, size_t count, int nchannels, bool srgb, double max_code,
                       T* out) {
    if (srgb && max_code == 255.0) {
        static const Srgb8 encode;
        for (size_t p = 0; p < count; ++p) {
            const float* px = in + p * 4;
            // A pixel with the bits of the one before it (the background, mostly) is stored as
            // that one was: a 16-byte compare costs less than three table walks.
            if (p > 0 && std::memcmp(px, px - 4, 4 * sizeof(float)) == 0) {
                std::copy_n(out + (p - 1) * nchannels, nchannels, out + p * nchannels);
                continue;
            }
            for (int c = 0; c < nchannels; ++c)
                out[p * nchannels + c] = T(c == 3 ? linear8(px[c]) : encode(px[c]));
        }
        return;
    }
    if (max_code == 255.0) {
#if defined(__AVX2__)
        if (nchannels == 3 || nchannels == 4) return linear8_avx2(in, count, nchannels, out);
#endif
        // The channel count as a constant, so that the compiler unrolls the pixel.
        auto linear = [&]<int kChannels>() {
            for (size_t p = 0; p < count; ++p)
                for (int c = 0; c < kChannels; ++c)
                    out[p * kChannels + c] = T(linear8(in[p * 4 + c]));
        };
        if (nchannels == 3) return linear.template operator()<3>();
        if (nchannels == 4) return linear.template operator()<4>();
        for (size_t p = 0; p < count; ++p)
            for (int c = 0; c < nchannels; ++c) out[p * nchannels + c] = T(linear8(in[p * 4 + c]));
        return;
    }
    for (size_t p = 0; p < count; ++p) {
        const float* px = in + p * 4;
        for (int c = 0; c < nchannels; ++c) {
            const bool is_alpha = c == 3;
            out[p * nchannels + c] = T(quantize(px[c], srgb && !is_alpha, max_code));
        }
    }
}

// Premultiplied colour -> straight (colour / alpha, 0 where alpha is 0 or less), in double.
void unpremultiply(const float* in, size_t count, float* out) {
    for (size_t p = 0; p < count; ++p, in += 4, out += 4) {
        const double a = finite_or_zero(in[3]);
        for (int c = 0; c < 3; ++c)
            out[c] = a > 0.0 ? float(double(finite_or_zero(in[c])) / a) : 0.0f;
        out[3] = in[3];
    }
}

// to_stored_samples, except that with 4 channels the colour of `in` is premultiplied and the file
// gets it straight (the convention of integer formats: PNG, TIFF, ...).
template <typename T>
void to_integer_samples(const float* in, size_t count, int nchannels, bool srgb, double max_code,
                        T* out) {
    if (nchannels != 4) return to_stored_samples(in, count, nchannels, srgb, max_code, out);
    constexpr size_t kBlock = 256;  // pixels converted at a time, on the stack
    float straight[kBlock * 4];
    for (size_t first = 0; first < count; first += kBlock) {
        const size_t n = std::min(kBlock, count - first);
        unpremultiply(in + first * 4, n, straight);
        to_stored_samples(straight, n, 4, srgb, max_code, out + first * 4);
    }
}

template <typename T>
std::vector<T> to_integer_samples(const Image& image, int nchannels, bool srgb, double max_code) {
    const size_t npix = size_t(image.width) * size_t(image.height);
    std::vector<T> out;
    resize_huge(out, npix * size_t(nchannels));
    to_integer_samples(image.rgba.data(), npix, nchannels, srgb, max_code, out.data());
    return out;
}

std::vector<float> to_float_samples(const Image& image, int nchannels, bool clamp_negative) {
    const size_t npix = size_t(image.width) * size_t(image.height);
    std::vector<float> out(npix * size_t(nchannels));
    for (size_t p = 0; p < npix; ++p) {
        const float* px = image.rgba.data() + p * 4;
        for (int c = 0; c < nchannels; ++c) {
            float v = finite_or_zero(px[c]);
            if (clamp_negative && v < 0.0f) v = 0.0f;
            out[p * nchannels + c] = v;
        }
    }
    return out;
}

// Binary PPM (P6), byte for byte what OpenImageIO's writer produced, written a block of rows at a
// time: `rows(first, count)` returns the 3-byte pixels of rows [first, first + count), valid until
// the next call.
template <class RowsFn>
bool write_ppm(const std::string& path, int width, int height, RowsFn&& rows, std::string& error) {
    FILE* f = open_output(path, error);
    if (!f) return false;
    const size_t row_bytes = size_t(width) * 3;
    const size_t block = std::max<size_t>(1, (size_t(64) << 10) / row_bytes);  // rows in ~64 KiB
    bool written = std::fprintf(f, "P6\n%d %d\n255\n", width, height) > 0;
    for (size_t y = 0; written && y < size_t(height); y += block) {
        const size_t n = std::min(block, size_t(height) - y);
        written = std::fwrite(rows(y, n), 1, n * row_bytes, f) == n * row_bytes;
    }
    const int write_errno = errno;
    std::string close_error;
    const bool closed = close_output(f, close_error);
    if (!written || !closed) {
        error = written ? close_error : std::string("write error: ") + std::strerror(write_errno);
        std::remove(path.c_str());
        return false;
    }
    return true;
}

// From float pixels, converted a block at a time: the block's buffer stays in cache, and no
// file-sized buffer is faulted in.
bool write_ppm(const std::string& path, const Image& image, bool srgb, std::string& error) {
    std::vector<uint8_t> block;
    const size_t width = size_t(image.width);
    return write_ppm(
        path, image.width, image.height,
        [&](size_t first, size_t count) {
            block.resize(count * width * 3);
            to_integer_samples<uint8_t>(image.rgba.data() + first * width * 4, count * width, 3,
                                        srgb, 255.0, block.data());
            return block.data();
        },
        error);
}

// Interleaved samples (nch a pixel) -> RGBA. The colour channels are the non-alpha ones in file
// order: one is grey (replicated), two or more give R, G (and B); a missing alpha is 1.
Image to_rgba(int width, int height, int nch, int alpha, const std::vector<float>& samples) {
    if (alpha < 0 && nch == 2) alpha = 1;  // grey + alpha without a name
    if (alpha >= nch) alpha = -1;
    std::vector<int> colour;
    for (int c = 0; c < nch && colour.size() < 3; ++c)
        if (c != alpha) colour.push_back(c);
    Image result(width, height);
    const size_t npix = size_t(width) * size_t(height);
    for (size_t p = 0; p < npix; ++p) {
        const float* src = samples.data() + p * size_t(nch);
        float* dst = result.rgba.data() + p * 4;
        if (colour.size() == 1) {
            dst[0] = dst[1] = dst[2] = src[colour[0]];
        } else {
            for (size_t c = 0; c < 3; ++c) dst[c] = c < colour.size() ? src[colour[c]] : 0.0f;
        }
        dst[3] = alpha >= 0 ? src[alpha] : 1.0f;
    }
    result.file_channels = nch;
    result.has_alpha = alpha >= 0;
    return result;
}

// The extensions of OpenImageIO 2.4's image writers (its "extension_list" for the formats of
// "output_format_list", less null and term). check_output refuses any other extension without
// loading the module (slow to load: oiio_abi.h); the module still has the last word on these.
bool oiio_may_write(const std::string& ext) {
    static constexpr const char* kKnown[] = {
        "exr",  "sxr",  "mxr",   "tif",  "tiff", "tx",   "env",  "sm",   "vsm",  "jpg",
        "jpe",  "jpeg", "jif",   "jfif", "jfi",  "bmp",  "dib",  "dpx",  "fits", "gif",
        "heic", "heif", "heics", "avif", "hdr",  "rgbe", "ico",  "iff",  "z",    "jp2",
        "j2k",  "j2c",  "png",   "ppm",  "pgm",  "pbm",  "pnm",  "pfm",  "rla",  "sgi",
        "rgb",  "rgba", "bw",    "int",  "inta", "tga",  "tpic", "webp", "zfile"};
    return std::find(std::begin(kKnown), std::end(kKnown), ext) != std::end(kKnown);
}

}  // namespace

int native_8bit_channels(const std::string& path, bool alpha) {
    const std::string ext = lower_extension(path);
    return ext == "png" ? (alpha ? 4 : 3) : ext == "ppm" ? 3 : 0;
}

OutputCheck check_output(const std::string& path, bool alpha, std::string& error) {
    namespace fs = std::filesystem;
    const std::string ext = lower_extension(path);
    if (ext.empty()) {
        error = "cannot write '" + path + "': no file extension to choose an image format by";
        return OutputCheck::kNotWritable;
    }
    // The folder first: it needs no OpenImageIO module to be loaded.
    fs::path folder = fs::path(path).parent_path();
    if (folder.empty()) folder = ".";
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) {
        error = "cannot write '" + path + "': the folder '" + folder.string() + "' does not exist";
        return OutputCheck::kNotWritable;
    }
    if (fs::is_directory(path, ec)) {
        error = "cannot write '" + path + "': it is a folder";
        return OutputCheck::kNotWritable;
    }
    const bool exists = fs::exists(path, ec);
    if (access(exists ? path.c_str() : folder.c_str(), W_OK) != 0) {
        error = "cannot write '" + path +
                "': " + (exists ? "the file" : "the folder '" + folder.string() + "'") +
                " is not writable (" + std::strerror(errno) + ")";
        return OutputCheck::kNotWritable;
    }
    int channels = native_8bit_channels(path, true);
    if (ext == "exr") {  // the OpenEXR module: no OpenImageIO needed
        std::string why;
        if (!exr_available(why)) {
            error = "cannot write EXR '" + path + "': " + why;
            return OutputCheck::kNotWritable;
        }
        channels = 4;
    }
    if (channels == 0) {
        if (!oiio_may_write(ext)) {
            error = "cannot write '" + path + "': unknown image format '." + ext + "'";
            return OutputCheck::kNotWritable;
        }
        std::string why;
        channels = oiio_output_channels(path, why);
        if (channels < 0) {
            error = "cannot write " + format_name(ext) + " '" + path + "': " + why;
            return OutputCheck::kNotWritable;
        }
        if (channels == 0) {
            error = "cannot write '" + path + "': unknown image format '." + ext + "'";
            return OutputCheck::kNotWritable;
        }
    }
    if (alpha && channels < 4) {
        error = "cannot write '" + path + "' with an alpha channel: " + format_name(ext) +
                " files have none (png, tif and exr do)";
        return OutputCheck::kNoAlpha;
    }
    return OutputCheck::kOk;
}

void encode_8bit(const float* rgba, size_t count, int channels, bool srgb, uint8_t* out) {
    to_integer_samples<uint8_t>(rgba, count, channels, srgb, 255.0, out);
}

bool encode_tile_8bit(const float* rgba, int x0, int y0, int x1, int y1, bool srgb, Image8& image) {
    const size_t n = size_t(x1 - x0), rows = size_t(y1 - y0), channels = size_t(image.channels);
    const size_t count = n * rows;
    auto at = [&](int y) {
        return &image.samples[(size_t(y) * size_t(image.width) + size_t(x0)) * channels];
    };
    // Each pixel equal to the one before it: all equal to the first. Encoding is per sample, so
    // one pixel's bytes are those every pixel would get.
    if (count > 1 && std::memcmp(rgba + 4, rgba, (count - 1) * 4 * sizeof(float)) == 0) {
        uint8_t one[4];
        encode_8bit(rgba, 1, image.channels, srgb, one);
        uint8_t* first = at(y0);
        for (size_t x = 0; x < n; ++x) std::copy_n(one, channels, first + x * channels);
        for (int y = y0 + 1; y < y1; ++y) std::copy_n(first, n * channels, at(y));
        return true;
    }
    for (int y = y0; y < y1; ++y, rgba += 4 * n) encode_8bit(rgba, n, image.channels, srgb, at(y));
    return false;
}

bool write_image8(const std::string& path, const Image8& image, bool srgb, std::string& error) {
    const int channels = native_8bit_channels(path, image.channels == 4);
    if (image.width <= 0 || image.height <= 0 || channels == 0 || image.channels != channels ||
        image.samples.size() != size_t(image.width) * size_t(image.height) * size_t(channels)) {
        error = "cannot write '" + path + "': the image is empty or malformed";
        return false;
    }
    std::string why;
    const bool ok = lower_extension(path) == "png"
                        ? write_png(path, image.width, image.height, channels, 8,
                                    image.samples.data(), srgb, why)
                        : write_ppm(
                              path, image.width, image.height,
                              [&](size_t first, size_t) {
                                  return image.samples.data() + first * size_t(image.width) * 3;
                              },
                              why);
    if (!ok) error = "cannot write '" + path + "': " + why;
    return ok;
}

bool write_image(const std::string& path, const Image& image, const WriteOptions& options,
                 std::string& error) {
    const bool srgb = options.srgb;
    const int want = options.alpha ? 4 : 3;
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != size_t(image.width) * size_t(image.height) * 4) {
        error = "cannot write '" + path + "': the image is empty or malformed";
        return false;
    }
    const std::string ext = lower_extension(path);
    if (ext.empty()) {
        error = "cannot write '" + path + "': no file extension to choose an image format by";
        return false;
    }
    std::string why;
    if (ext == "png") {
        // 8-bit: the common case never loads the module.
        const std::vector<uint8_t> samples = to_integer_samples<uint8_t>(image, want, srgb, 255.0);
        if (write_png(path, image.width, image.height, want, 8, samples.data(), srgb, why))
            return true;
        error = "cannot write '" + path + "': " + why;
        return false;
    }
    if (ext == "ppm") {
        if (options.alpha) {
            error = "cannot write '" + path + "' with an alpha channel: PPM files have none";
            return false;
        }
        if (write_ppm(path, image, srgb, why)) return true;
        error = "cannot write '" + path + "': " + why;
        return false;
    }

    if (ext == "exr") {
        // Float, unclamped; colour premultiplied with alpha, as EXR readers expect.
        const std::vector<float> samples = to_float_samples(image, want, false);
        if (write_exr(path, image.width, image.height, want, samples.data(), why)) return true;
        error = "cannot write '" + path + "': " + why;
        return false;
    }
    const int format_channels = oiio_output_channels(path, why);
    if (format_channels < 0) {
        error = "cannot write " + format_name(ext) + " '" + path + "': " + why;
        return false;
    }
    if (format_channels == 0) {
        error = "cannot write '" + path + "': unknown image format '." + ext + "'";
        return false;
    }
    if (want > format_channels) {
        error = "cannot write '" + path + "' with an alpha channel: " + format_name(ext) +
                " files have none";
        return false;
    }
    const int nchannels = want;
    const FormatChoice format = choose_format(ext);
    bool ok = false;
    switch (format.kind) {
        case SampleKind::kUint8: {
            auto samples = to_integer_samples<uint8_t>(image, nchannels, srgb, 255.0);
            ok = oiio_write_pixels(path, image.width, image.height, nchannels, VR_OIIO_UINT8,
                                   samples.data(), srgb, why);
            break;
        }
        case SampleKind::kUint16: {
            auto samples = to_integer_samples<uint16_t>(image, nchannels, srgb, 65535.0);
            ok = oiio_write_pixels(path, image.width, image.height, nchannels, VR_OIIO_UINT16,
                                   samples.data(), srgb, why);
            break;
        }
        case SampleKind::kFloat: {
            auto samples = to_float_samples(image, nchannels, format.clamp_negative);
            ok = oiio_write_pixels(path, image.width, image.height, nchannels, VR_OIIO_FLOAT,
                                   samples.data(), srgb, why);
            break;
        }
    }
    if (!ok) {
        error = "cannot write '" + path + "': " + why;
        return false;
    }
    return true;
}

bool read_image(const std::string& path, Image& image, std::string& error) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
        error = "cannot read '" + path + "': no such file";
        return false;
    }
    std::string why, format;
    FilePixels pixels;
    if (!read_file_pixels(path, INT_MAX, kMaxImagePixels, pixels, why, format)) {
        error = "cannot read " + (format.empty() ? std::string() : format + " ") + "'" + path +
                "': " + why;
        return false;
    }
    image =
        to_rgba(pixels.width, pixels.height, pixels.channels, pixels.alpha_channel, pixels.samples);
    return true;
}

}  // namespace vr
