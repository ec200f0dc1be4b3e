// Reading and writing float RGBA images through OpenImageIO.
//
// What reaches a file (SPEC section 9):
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
//   - RGBA where the format has alpha (png, exr, tif, tga, ...), RGB otherwise (jpg, ppm, hdr).
//   - No NaN or infinity is ever written: NaN becomes 0, +-infinity the largest finite float of
//     its sign (then clamped like any other value).
//   - Colour is stored exactly as computed, not divided or multiplied by alpha: the files are
//     marked (and read back) as unassociated alpha so that OpenImageIO does not premultiply or
//     un-premultiply.
// Reading returns the stored values as floats (8/16-bit code k as the float nearest k/255 or
// k/65535), no transfer curve undone.
#include "image/image.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>

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

std::string oiio_error(const std::string& specific) {
    std::string global = OIIO::geterror();
    if (!specific.empty()) return specific;
    if (!global.empty()) return global;
    return "unknown OpenImageIO error";
}

// Converts `image` to the interleaved samples stored in the file (nchannels per pixel).
template <typename T>
std::vector<T> to_integer_samples(const Image& image, int nchannels, bool srgb, double max_code) {
    const size_t npix = size_t(image.width) * size_t(image.height);
    std::vector<T> out(npix * size_t(nchannels));
    for (size_t p = 0; p < npix; ++p) {
        const float* px = image.rgba.data() + p * 4;
        for (int c = 0; c < nchannels; ++c) {
            const bool is_alpha = c == 3;
            out[p * nchannels + c] = T(quantize(px[c], srgb && !is_alpha, max_code));
        }
    }
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

}  // namespace

bool write_image(const std::string& path, const Image& image, bool srgb, std::string& error) {
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != size_t(image.width) * size_t(image.height) * 4) {
        error = "cannot write '" + path + "': the image is empty or malformed";
        return false;
    }
    const std::string ext = lower_extension(path);
    auto out = OIIO::ImageOutput::create(path);
    if (!out) {
        OIIO::geterror();  // drop the pending message; ours names the extension
        error = "cannot write '" + path + "': " +
                (ext.empty() ? std::string("no file extension to choose an image format by")
                             : "unknown image format '." + ext + "'");
        return false;
    }
    const FormatChoice format = choose_format(ext);
    const int nchannels = out->supports("alpha") ? 4 : 3;

    OIIO::TypeDesc type = OIIO::TypeDesc::UINT8;
    if (format.kind == SampleKind::kUint16) type = OIIO::TypeDesc::UINT16;
    if (format.kind == SampleKind::kFloat) type = OIIO::TypeDesc::FLOAT;

    OIIO::ImageSpec spec(image.width, image.height, nchannels, type);
    if (nchannels == 4) {
        spec.alpha_channel = 3;
        spec.attribute("oiio:UnassociatedAlpha", 1);
    }
    if (format.kind != SampleKind::kFloat && srgb) spec.attribute("oiio:ColorSpace", "sRGB");
    if (ext == "exr") spec.attribute("compression", "zip");
    if (ext == "jpg" || ext == "jpeg") spec.attribute("Compression", "jpeg:95");
    if (ext == "ppm" || ext == "pnm") spec.attribute("pnm:binary", 1);
    spec.attribute("Software", "vrmlray");

    if (!out->open(path, spec)) {
        error = "cannot write '" + path + "': " + oiio_error(out->geterror());
        return false;
    }
    bool ok = false;
    switch (format.kind) {
        case SampleKind::kUint8: {
            auto samples = to_integer_samples<uint8_t>(image, nchannels, srgb, 255.0);
            ok = out->write_image(OIIO::TypeDesc::UINT8, samples.data());
            break;
        }
        case SampleKind::kUint16: {
            auto samples = to_integer_samples<uint16_t>(image, nchannels, srgb, 65535.0);
            ok = out->write_image(OIIO::TypeDesc::UINT16, samples.data());
            break;
        }
        case SampleKind::kFloat: {
            auto samples = to_float_samples(image, nchannels, format.clamp_negative);
            ok = out->write_image(OIIO::TypeDesc::FLOAT, samples.data());
            break;
        }
    }
    const bool closed = out->close();
    if (!ok || !closed) {
        error = "cannot write '" + path + "': " + oiio_error(out->geterror());
        return false;
    }
    return true;
}

bool read_image(const std::string& path, Image& image, std::string& error) {
    // Keep alpha unassociated so colour comes back exactly as stored.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) {
        std::string why = oiio_error("");
        if (!std::filesystem::exists(path)) why = "no such file";
        error = "cannot read '" + path + "': " + why;
        return false;
    }
    const OIIO::ImageSpec& spec = in->spec();
    const int nch = spec.nchannels;
    if (spec.width <= 0 || spec.height <= 0 || nch <= 0 || spec.deep) {
        error = "cannot read '" + path + "': not a flat image with pixels";
        return false;
    }
    const size_t npix = size_t(spec.width) * size_t(spec.height);
    std::vector<float> samples(npix * size_t(nch));
    // 8- and 16-bit files are read as integers and divided here, so that code k becomes exactly the
    // float nearest k/255 (OpenImageIO's own conversion multiplies by a rounded reciprocal).
    bool ok = false;
    if (spec.format == OIIO::TypeDesc::UINT8) {
        std::vector<uint8_t> codes(samples.size());
        ok = in->read_image(0, 0, 0, nch, OIIO::TypeDesc::UINT8, codes.data());
        for (size_t i = 0; i < codes.size(); ++i) samples[i] = float(codes[i]) / 255.0f;
    } else if (spec.format == OIIO::TypeDesc::UINT16) {
        std::vector<uint16_t> codes(samples.size());
        ok = in->read_image(0, 0, 0, nch, OIIO::TypeDesc::UINT16, codes.data());
        for (size_t i = 0; i < codes.size(); ++i) samples[i] = float(codes[i]) / 65535.0f;
    } else {
        ok = in->read_image(0, 0, 0, nch, OIIO::TypeDesc::FLOAT, samples.data());
    }
    if (!ok) {
        error = "cannot read '" + path + "': " + oiio_error(in->geterror());
        return false;
    }
    in->close();

    // The colour channels are the non-alpha ones in file order: one is grey (replicated), two or
    // more give R, G (and B); a missing alpha is 1.
    int alpha = spec.alpha_channel;
    if (alpha < 0 && nch == 2) alpha = 1;  // grey + alpha without a name
    if (alpha >= nch) alpha = -1;
    std::vector<int> colour;
    for (int c = 0; c < nch && colour.size() < 3; ++c)
        if (c != alpha) colour.push_back(c);

    Image result(spec.width, spec.height);
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
    image = std::move(result);
    return true;
}

}  // namespace vr
