// PNG through libpng. libpng reports errors by longjmp: every function that calls it with a
// setjmp below holds no object with a destructor that is created after the setjmp, and the buffers
// it fills belong to its caller, so a jump skips nothing that needs cleaning up.
#include "image/png.h"

#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

#include "image/output_file.h"

namespace vr {
namespace {

// Where libpng's messages go; the first error is kept.
struct Messages {
    char error[256] = "";
};

// libpng's words, with what they mean to a user where they are terse.
[[noreturn]] void on_error(png_structp png, png_const_charp message) {
    auto* m = static_cast<Messages*>(png_get_error_ptr(png));
    if (m && m->error[0] == '\0') {
        const char* format = "%s";
        if (std::strcmp(message, "Not enough image data") == 0)
            format = "the image data is truncated (%s)";
        else if (std::strncmp(message, "IDAT: ", 6) == 0 && !std::strstr(message, "CRC"))
            format = "bad compressed image data (%s)";
        std::snprintf(m->error, sizeof m->error, format, message);
    }
    png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // ancillary damage: libpng drops the chunk

// The file, in memory or open. `size` is its length in bytes (a bound on the image data).
struct Source {
    const uint8_t* data = nullptr;  // in memory, else `file`
    FILE* file = nullptr;
    size_t size = 0, at = 0;
    // After the image data: a file that ends before IEND is forgiven (as by OpenImageIO, which
    // never reads past the image), once the last chunk before the cut was whole and its CRC
    // checked.
    bool after_image = false, saw_iend = false, ended_early = false;
};

void read_source(png_structp png, png_bytep out, size_t count) {
    auto* src = static_cast<Source*>(png_get_io_ptr(png));
    size_t got = 0;
    if (src->data) {
        got = std::min(count, src->size - src->at);
        std::memcpy(out, src->data + src->at, got);
    } else {
        got = std::fread(out, 1, count, src->file);
    }
    src->at += got;
    if (got == count) {
        if (src->after_image && count == 8 && std::memcmp(out + 4, "IEND", 4) == 0)
            src->saw_iend = true;
        return;
    }
    // libpng reads a chunk header as 8 bytes: a cut there follows a whole, checked chunk.
    if (src->after_image && (count == 8 || src->saw_iend)) {
        src->ended_early = true;
        png_longjmp(png, 1);
    }
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
std::string too_large(unsigned long long w, unsigned long long h, size_t max_pixels) {
    return "the image is too large (" + std::to_string(w) + " x " + std::to_string(h) + " = " +
           std::to_string(w * h) + " pixels; the limit is " + std::to_string(max_pixels) + ")";
}

// The size IHDR claims, checked from the file's first 24 bytes before libpng reads on (it would
// first read every chunk up to the image data).
bool claimed_size_fits(const uint8_t* head, size_t size, size_t max_pixels, std::string& error) {
    if (size < 24 || std::memcmp(head + 12, "IHDR", 4) != 0) return true;  // libpng will say why
    auto be32 = [](const uint8_t* b) {
        return (unsigned long long)b[0] << 24 | b[1] << 16 | b[2] << 8 | b[3];
    };
    const unsigned long long w = be32(head + 16), h = be32(head + 20);
    if (w * h <= max_pixels) return true;
    error = too_large(w, h, max_pixels);
    return false;
}

bool read_header(Reader& r, const Source& src, size_t max_pixels, Layout& layout,
                 std::string& error) {
    if (setjmp(png_jmpbuf(r.png))) {
        error = r.messages.error;
        return false;
    }
    png_read_info(r.png, r.info);
    png_uint_32 w = 0, h = 0;
    int depth = 0, colour = 0, interlace = 0;
    png_get_IHDR(r.png, r.info, &w, &h, &depth, &colour, &interlace, nullptr, nullptr);
    if ((unsigned long long)w * h > max_pixels) {
        error = too_large(w, h, max_pixels);
        return false;
    }
    // Deflate expands at most ~1032:1: a claimed image its file could not hold is refused before
    // its memory exists (else 60 bytes could ask for gigabytes). The file's rows, filter byte each.
    const unsigned long long stored = (unsigned long long)h * (png_get_rowbytes(r.png, r.info) + 1);
    if (stored / 1032 > src.size) {
        std::snprintf(r.messages.error, sizeof r.messages.error,
                      "the image data (%zu bytes) is too short for a %u x %u image", src.size,
                      unsigned(w), unsigned(h));
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

bool read_rows(Reader& r, Source& src, png_bytep* rows, std::string& error) {
    if (setjmp(png_jmpbuf(r.png))) {
        if (src.ended_early) return true;
        error = r.messages.error;
        return false;
    }
    png_read_image(r.png, rows);
    src.after_image = true;
    png_read_end(r.png, nullptr);  // the image data's CRCs and Adler-32 checksum
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

PngStatus decode(Reader& r, Source& src, size_t max_pixels, PngPixels& pixels, std::string& error) {
    png_set_read_fn(r.png, &src, read_source);
    Layout layout;
    if (!read_header(r, src, max_pixels, layout, error)) return PngStatus::kError;
    std::vector<uint8_t> raw(layout.row_bytes * layout.height);
    std::vector<png_bytep> rows(layout.height);
    for (png_uint_32 y = 0; y < layout.height; ++y) rows[y] = raw.data() + y * layout.row_bytes;
    if (!read_rows(r, src, rows.data(), error)) return PngStatus::kError;
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
    if (!claimed_size_fits(data, size, max_pixels, error)) return PngStatus::kError;
    Reader r;
    if (!start_reader(r, error)) return PngStatus::kError;
    Source src;
    src.data = data;
    src.size = size;
    return decode(r, src, max_pixels, pixels, error);
}

PngStatus read_png(const std::string& path, size_t max_pixels, PngPixels& pixels,
                   std::string& error) {
    File f(std::fopen(path.c_str(), "rb"));
    if (!f) {
        error = std::strerror(errno);
        return PngStatus::kError;
    }
    uint8_t head[24];
    const size_t got = std::fread(head, 1, sizeof head, f.get());
    if (got < 8 || png_sig_cmp(head, 0, 8) != 0) return PngStatus::kNotPng;
    if (!claimed_size_fits(head, got, max_pixels, error)) return PngStatus::kError;
    Reader r;
    if (!start_reader(r, error)) return PngStatus::kError;
    Source src;
    src.file = f.get();
    if (std::fseek(f.get(), 0, SEEK_END) != 0 || std::ftell(f.get()) < 0) {
        error = "cannot find the file's size";
        return PngStatus::kError;
    }
    src.size = size_t(std::ftell(f.get()));
    std::fseek(f.get(), 0, SEEK_SET);
    return decode(r, src, max_pixels, pixels, error);
}

namespace {

// One encoding of the image into memory.
struct Encoding {
    std::vector<uint8_t> bytes;
    Messages messages;
    bool ok = false;
};

struct Writer {
    png_structp png = nullptr;
    png_infop info = nullptr;
    ~Writer() { png_destroy_write_struct(&png, info ? &info : nullptr); }
};

void append_bytes(png_structp png, png_bytep data, size_t count) {
    auto* out = static_cast<std::vector<uint8_t>*>(png_get_io_ptr(png));
    out->insert(out->end(), data, data + count);
}

void no_flush(png_structp) {}

// Filters: libpng's default for 8- and 16-bit images tries all five per row and keeps the one with
// the smallest sum of absolute filtered bytes (the hand-written writer's rule too).
bool encode_rows(Writer& w, Encoding& out, int width, int height, int channels, int bit_depth,
                 const uint8_t* samples, bool srgb, int strategy) {
    static constexpr int kColourType[] = {0, PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA,
                                          PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
    static char kKey[] = "Software", kValue[] = "vrmlray";
    if (setjmp(png_jmpbuf(w.png))) return false;
    png_set_write_fn(w.png, &out.bytes, append_bytes, no_flush);
    png_set_compression_level(w.png, 6);  // level 9 saves 2% more but triples the time
    png_set_compression_strategy(w.png, strategy);
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

void encode(Encoding& out, int width, int height, int channels, int bit_depth,
            const uint8_t* samples, bool srgb, int strategy) {
    Writer w;
    w.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &out.messages, on_error, on_warning);
    if (w.png) w.info = png_create_info_struct(w.png);
    if (!w.info) {
        std::snprintf(out.messages.error, sizeof out.messages.error, "out of memory");
        return;
    }
    out.ok = encode_rows(w, out, width, height, channels, bit_depth, samples, srgb, strategy);
}

}  // namespace

bool write_png(const std::string& path, int width, int height, int channels, int bit_depth,
               const void* samples, bool srgb, std::string& error) {
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4 ||
        (bit_depth != 8 && bit_depth != 16)) {
        error = "bad image layout for PNG";
        return false;
    }
    File f(open_output(path, error));
    if (!f) return false;
    // zlib's filtered strategy (the hand-written writer's) and its default strategy each win on
    // some images: the default is 4% smaller over the golden images, the filtered one up to 6%
    // smaller on gas images. Both are encoded, one per core, and the smaller is kept, so a file
    // is never larger than the hand-written writer's and the wall time stays that of one.
    const auto* bytes = static_cast<const uint8_t*>(samples);
    Encoding filtered, plain;
    std::thread other(
        [&] { encode(filtered, width, height, channels, bit_depth, bytes, srgb, Z_FILTERED); });
    encode(plain, width, height, channels, bit_depth, bytes, srgb, Z_DEFAULT_STRATEGY);
    other.join();
    const Encoding& best = !filtered.ok || (plain.ok && plain.bytes.size() <= filtered.bytes.size())
                               ? plain
                               : filtered;
    bool ok = best.ok;
    if (!ok) error = best.messages.error;
    if (ok && std::fwrite(best.bytes.data(), 1, best.bytes.size(), f.get()) != best.bytes.size())
        ok = false;
    const int write_errno = errno;
    std::string close_error;
    const bool closed = close_output(f.release(), close_error);
    if (best.ok && (!ok || !closed)) {
        error = ok ? close_error : std::string("write error: ") + std::strerror(write_errno);
        ok = false;
    }
    if (!ok) std::remove(path.c_str());
    return ok;
}

}  // namespace vr
