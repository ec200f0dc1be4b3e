// PNG through libpng. libpng reports errors by longjmp: every function that calls it with a
// setjmp below holds no object with a destructor that is created after the setjmp, and the buffers
// it fills belong to its caller, so a jump skips nothing that needs cleaning up.
#include "image/png.h"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>

namespace vr {
namespace {

// Where libpng's messages go; the first error is kept.
struct Messages {
    char error[256] = "";
};

[[noreturn]] void on_error(png_structp png, png_const_charp message) {
    auto* m = static_cast<Messages*>(png_get_error_ptr(png));
    if (m && m->error[0] == '\0') std::snprintf(m->error, sizeof m->error, "%s", message);
    png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // ancillary damage: libpng drops the chunk

// An in-memory file.
struct MemorySource {
    const uint8_t* data = nullptr;
    size_t size = 0, at = 0;
};

void read_memory(png_structp png, png_bytep out, size_t count) {
    auto* src = static_cast<MemorySource*>(png_get_io_ptr(png));
    if (count > src->size - src->at) png_error(png, "the file is truncated");
    std::memcpy(out, src->data + src->at, count);
    src->at += count;
}

void read_stdio(png_structp png, png_bytep out, size_t count) {
    if (std::fread(out, 1, count, static_cast<FILE*>(png_get_io_ptr(png))) != count)
        png_error(png, "the file is truncated");
}

struct Reader {
    png_structp png = nullptr;
    png_infop info = nullptr;
    Messages messages;
    ~Reader() { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); }
};

struct Layout {
    png_uint_32 width = 0, height = 0;
    int channels = 0, bit_depth = 0;
    size_t row_bytes = 0;
};

// Reads the header and asks libpng for the samples png.h promises: palette to RGB, tRNS to alpha,
// 1/2/4-bit grey scaled to 8 bits (libpng replicates the bits: v * 255 / (2^d - 1)), 16 bits kept
// (big-endian, as stored), Adam7 deinterlaced.
bool read_header(Reader& r, size_t max_pixels, Layout& layout, std::string& error) {
    if (setjmp(png_jmpbuf(r.png))) {
        error = r.messages.error;
        return false;
    }
    png_read_info(r.png, r.info);
    png_uint_32 w = 0, h = 0;
    int depth = 0, colour = 0, interlace = 0;
    png_get_IHDR(r.png, r.info, &w, &h, &depth, &colour, &interlace, nullptr, nullptr);
    const unsigned long long pixels = (unsigned long long)w * h;
    if (pixels > max_pixels) {
        std::snprintf(r.messages.error, sizeof r.messages.error,
                      "the image is too large (%u x %u = %llu pixels; the limit is %zu)", unsigned(w),
                      unsigned(h), pixels, max_pixels);
        error = r.messages.error;
        return false;
    }
    png_set_expand(r.png);
    if (interlace != PNG_INTERLACE_NONE) png_set_interlace_handling(r.png);
    png_read_update_info(r.png, r.info);
    layout.width = w, layout.height = h;
    layout.channels = png_get_channels(r.png, r.info);
    layout.bit_depth = png_get_bit_depth(r.png, r.info);
    layout.row_bytes = png_get_rowbytes(r.png, r.info);
    return true;
}

bool read_rows(Reader& r, png_bytep* rows, std::string& error) {
    if (setjmp(png_jmpbuf(r.png))) {
        error = r.messages.error;
        return false;
    }
    png_read_image(r.png, rows);
    png_read_end(r.png, nullptr);  // the CRCs and data up to IEND: a truncated file is an error
    return true;
}

// Code k as the float nearest k / max (divided, not multiplied by a reciprocal).
void to_floats(const std::vector<uint8_t>& raw, const Layout& l, PngPixels& pixels) {
    const size_t count = size_t(l.width) * l.height * size_t(l.channels);
    pixels.width = int(l.width), pixels.height = int(l.height);
    pixels.channels = l.channels, pixels.bit_depth = l.bit_depth;
    pixels.samples.resize(count);
    if (l.bit_depth == 16) {
        for (size_t i = 0; i < count; ++i)
            pixels.samples[i] = float(double((raw[2 * i] << 8) | raw[2 * i + 1]) / 65535.0);
    } else {
        for (size_t i = 0; i < count; ++i) pixels.samples[i] = float(double(raw[i]) / 255.0);
    }
}

PngStatus decode(Reader& r, size_t max_pixels, PngPixels& pixels, std::string& error) {
    png_set_error_fn(r.png, &r.messages, on_error, on_warning);
    Layout layout;
    if (!read_header(r, max_pixels, layout, error)) return PngStatus::kError;
    std::vector<uint8_t> raw(layout.row_bytes * layout.height);
    std::vector<png_bytep> rows(layout.height);
    for (png_uint_32 y = 0; y < layout.height; ++y) rows[y] = raw.data() + y * layout.row_bytes;
    if (!read_rows(r, rows.data(), error)) return PngStatus::kError;
    to_floats(raw, layout, pixels);
    return PngStatus::kOk;
}

bool start_reader(Reader& r, std::string& error) {
    r.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &r.messages, on_error, on_warning);
    if (r.png) r.info = png_create_info_struct(r.png);
    if (!r.info) error = "out of memory";
    return r.info != nullptr;
}

struct FileCloser {
    void operator()(FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<FILE, FileCloser>;

}  // namespace

PngStatus decode_png(const uint8_t* data, size_t size, size_t max_pixels, PngPixels& pixels,
                     std::string& error) {
    if (size < 8 || png_sig_cmp(data, 0, 8) != 0) return PngStatus::kNotPng;
    Reader r;
    if (!start_reader(r, error)) return PngStatus::kError;
    MemorySource src{data, size, 0};
    png_set_read_fn(r.png, &src, read_memory);
    return decode(r, max_pixels, pixels, error);
}

PngStatus read_png(const std::string& path, size_t max_pixels, PngPixels& pixels,
                   std::string& error) {
    File f(std::fopen(path.c_str(), "rb"));
    if (!f) {
        error = std::strerror(errno);
        return PngStatus::kError;
    }
    uint8_t signature[8];
    if (std::fread(signature, 1, 8, f.get()) != 8 || png_sig_cmp(signature, 0, 8) != 0)
        return PngStatus::kNotPng;
    Reader r;
    if (!start_reader(r, error)) return PngStatus::kError;
    png_set_read_fn(r.png, f.get(), read_stdio);
    png_set_sig_bytes(r.png, 8);
    return decode(r, max_pixels, pixels, error);
}

namespace {

struct Writer {
    png_structp png = nullptr;
    png_infop info = nullptr;
    Messages messages;
    ~Writer() { png_destroy_write_struct(&png, info ? &info : nullptr); }
};

// Filters: libpng's default for 8- and 16-bit images tries all five per row and keeps the one with
// the smallest sum of absolute filtered bytes. zlib level 9 (libpng's default is 6): the images
// are small next to the render, and every byte saved is kept.
bool write_rows(Writer& w, FILE* file, int width, int height, int channels, int bit_depth,
                const uint8_t* samples, bool srgb, std::string& error) {
    static constexpr int kColourType[] = {0, PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA,
                                          PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
    static char kKey[] = "Software", kValue[] = "vrmlray";
    if (setjmp(png_jmpbuf(w.png))) {
        error = w.messages.error;
        return false;
    }
    png_init_io(w.png, file);
    png_set_compression_level(w.png, 9);
    png_set_IHDR(w.png, w.info, png_uint_32(width), png_uint_32(height), bit_depth,
                 kColourType[channels], PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    // OpenImageIO's chunks for an sRGB image: sRGB (perceptual), gAMA 1/2.2 and the sRGB cHRM.
    if (srgb) png_set_sRGB_gAMA_and_cHRM(w.png, w.info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_text text{};
    text.compression = PNG_TEXT_COMPRESSION_NONE;
    text.key = kKey;
    text.text = kValue;
    png_set_text(w.png, w.info, &text, 1);
    png_write_info(w.png, w.info);
    if (bit_depth == 16) png_set_swap(w.png);  // host order (little-endian) in, big-endian out
    const size_t row_bytes = size_t(width) * size_t(channels) * size_t(bit_depth / 8);
    for (int y = 0; y < height; ++y)
        png_write_row(w.png, const_cast<png_bytep>(samples + size_t(y) * row_bytes));
    png_write_end(w.png, nullptr);
    return true;
}

}  // namespace

bool write_png(const std::string& path, int width, int height, int channels, int bit_depth,
               const void* samples, bool srgb, std::string& error) {
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4 ||
        (bit_depth != 8 && bit_depth != 16)) {
        error = "bad image layout for PNG";
        return false;
    }
    File f(std::fopen(path.c_str(), "wb"));
    if (!f) {
        error = std::strerror(errno);
        return false;
    }
    bool ok = false;
    {
        Writer w;
        w.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &w.messages, on_error, on_warning);
        if (w.png) w.info = png_create_info_struct(w.png);
        if (!w.info) error = "out of memory";
        else
            ok = write_rows(w, f.get(), width, height, channels, bit_depth,
                            static_cast<const uint8_t*>(samples), srgb, error);
    }
    const bool flushed = std::fflush(f.get()) == 0 && !std::ferror(f.get());
    const bool closed = std::fclose(f.release()) == 0;
    if (ok && (!flushed || !closed)) {
        error = std::string("write error: ") + std::strerror(errno);
        ok = false;
    }
    if (!ok) std::remove(path.c_str());
    return ok;
}

}  // namespace vr
