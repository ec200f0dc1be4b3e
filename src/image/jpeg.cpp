// libjpeg reports errors through error_exit, which must not return: it longjmps back here. The
// functions with a setjmp create no object with a destructor after it; buffers are their caller's.
#include "image/jpeg.h"

#include <jpeglib.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>

namespace vr {
namespace {

struct ErrorManager {
    jpeg_error_mgr base;
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX] = "";
};

[[noreturn]] void on_error(j_common_ptr cinfo) {
    auto* e = reinterpret_cast<ErrorManager*>(cinfo->err);
    (*cinfo->err->format_message)(cinfo, e->message);
    std::longjmp(e->jump, 1);
}

void on_message(j_common_ptr, int) {}  // warnings (e.g. premature end of data) are not fatal

struct Decoder {
    jpeg_decompress_struct cinfo{};
    ErrorManager err;
    bool started = false;
    ~Decoder() {
        if (started) jpeg_destroy_decompress(&cinfo);
    }
};

enum class Step { kOk, kUnsupported, kError };

Step read_header(Decoder& d, FILE* file, size_t max_pixels, std::string& error) {
    d.cinfo.err = jpeg_std_error(&d.err.base);
    d.err.base.error_exit = on_error;
    d.err.base.emit_message = on_message;
    if (setjmp(d.err.jump)) {
        error = d.err.message;
        return Step::kError;
    }
    jpeg_create_decompress(&d.cinfo);
    d.started = true;
    jpeg_stdio_src(&d.cinfo, file);
    jpeg_read_header(&d.cinfo, TRUE);
    if (d.cinfo.jpeg_color_space == JCS_CMYK || d.cinfo.jpeg_color_space == JCS_YCCK)
        return Step::kUnsupported;
    const unsigned long long pixels =
        (unsigned long long)d.cinfo.image_width * d.cinfo.image_height;
    if (pixels > max_pixels) {
        std::snprintf(d.err.message, sizeof d.err.message,
                      "the image is too large (%u x %u = %llu pixels; the limit is %zu)",
                      unsigned(d.cinfo.image_width), unsigned(d.cinfo.image_height), pixels,
                      max_pixels);
        error = d.err.message;
        return Step::kError;
    }
    d.cinfo.out_color_space = d.cinfo.num_components == 1 ? JCS_GRAYSCALE : JCS_RGB;
    jpeg_start_decompress(&d.cinfo);
    return Step::kOk;
}

bool read_rows(Decoder& d, uint8_t* out, std::string& error) {
    if (setjmp(d.err.jump)) {
        error = d.err.message;
        return false;
    }
    const size_t row = size_t(d.cinfo.output_width) * size_t(d.cinfo.output_components);
    while (d.cinfo.output_scanline < d.cinfo.output_height) {
        JSAMPROW line = out + size_t(d.cinfo.output_scanline) * row;
        jpeg_read_scanlines(&d.cinfo, &line, 1);
    }
    jpeg_finish_decompress(&d.cinfo);
    return true;
}

struct FileCloser {
    void operator()(FILE* f) const { std::fclose(f); }
};

}  // namespace

JpegStatus read_jpeg(const std::string& path, size_t max_pixels, JpegPixels& pixels,
                     std::string& error) {
    std::unique_ptr<FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
    if (!f) {
        error = std::strerror(errno);
        return JpegStatus::kError;
    }
    unsigned char signature[3] = {};
    if (std::fread(signature, 1, 3, f.get()) != 3 || signature[0] != 0xFF || signature[1] != 0xD8 ||
        signature[2] != 0xFF)
        return JpegStatus::kNotJpeg;
    std::rewind(f.get());
    Decoder d;
    const Step step = read_header(d, f.get(), max_pixels, error);
    if (step == Step::kUnsupported) return JpegStatus::kUnsupported;
    if (step == Step::kError) return JpegStatus::kError;
    const size_t count =
        size_t(d.cinfo.output_width) * d.cinfo.output_height * size_t(d.cinfo.output_components);
    std::vector<uint8_t> raw(count);
    if (!read_rows(d, raw.data(), error)) return JpegStatus::kError;
    pixels.width = int(d.cinfo.output_width);
    pixels.height = int(d.cinfo.output_height);
    pixels.channels = d.cinfo.output_components;
    pixels.samples.resize(count);
    for (size_t i = 0; i < count; ++i) pixels.samples[i] = float(double(raw[i]) / 255.0);
    return JpegStatus::kOk;
}

}  // namespace vr
