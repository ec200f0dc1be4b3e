// vrmlray_oiio.so: the only code that links OpenImageIO, loaded by src/image/oiio_module.cpp when
// an image format other than the native ones (PNG, PPM) is read or written. See
// src/image/oiio_abi.h for the interface and why it exists.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

#include "image/oiio_abi.h"

namespace {

void set_error(char* error, size_t error_size, const std::string& message) {
    if (!error || error_size == 0) return;
    const size_t n = std::min(message.size(), error_size - 1);
    std::memcpy(error, message.data(), n);
    error[n] = '\0';
}

// The object's own message, else OpenImageIO's global one, else a generic one.
std::string oiio_error(const std::string& specific) {
    std::string global = OIIO::geterror();
    if (!specific.empty()) return specific;
    if (!global.empty()) return global;
    return "unknown OpenImageIO error";
}

OIIO::TypeDesc type_of(int format) {
    if (format == VR_OIIO_UINT8) return OIIO::TypeDesc::UINT8;
    if (format == VR_OIIO_UINT16) return OIIO::TypeDesc::UINT16;
    return OIIO::TypeDesc::FLOAT;
}

std::string lower_extension(const char* path) {
    std::string ext = std::filesystem::path(path).extension().string();
    if (!ext.empty() && ext[0] == '.') ext.erase(0, 1);
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

}  // namespace

struct VrOiioInput {
    std::unique_ptr<OIIO::ImageInput> input;
};

extern "C" {

int vrmlray_oiio_abi_version(void) { return VRMLRAY_OIIO_ABI_VERSION; }

VrOiioInput* vrmlray_oiio_open(const char* path, int unassociated_alpha, VrOiioSpec* spec,
                               char* error, size_t error_size) {
    try {
        OIIO::ImageSpec config;
        if (unassociated_alpha) config.attribute("oiio:UnassociatedAlpha", 1);
        auto in = OIIO::ImageInput::open(path, &config);
        if (!in) {
            set_error(error, error_size, oiio_error(""));
            return nullptr;
        }
        const OIIO::ImageSpec& s = in->spec();
        spec->width = s.width;
        spec->height = s.height;
        spec->channels = s.nchannels;
        spec->format = s.format == OIIO::TypeDesc::UINT8    ? VR_OIIO_UINT8
                       : s.format == OIIO::TypeDesc::UINT16 ? VR_OIIO_UINT16
                                                            : VR_OIIO_FLOAT;
        spec->alpha_channel = s.alpha_channel;
        spec->deep = s.deep ? 1 : 0;
        auto* result = new VrOiioInput;
        result->input = std::move(in);
        return result;
    } catch (const std::exception& e) {
        set_error(error, error_size, e.what());
        return nullptr;
    }
}

int vrmlray_oiio_read(VrOiioInput* input, int channels, int format, void* samples, char* error,
                      size_t error_size) {
    try {
        if (!input->input->read_image(0, 0, 0, channels, type_of(format), samples)) {
            set_error(error, error_size, oiio_error(input->input->geterror()));
            return 0;
        }
        return 1;
    } catch (const std::exception& e) {
        set_error(error, error_size, e.what());
        return 0;
    }
}

void vrmlray_oiio_close(VrOiioInput* input) {
    if (!input) return;
    if (input->input) input->input->close();
    delete input;
}

int vrmlray_oiio_output_channels(const char* path) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) {
        OIIO::geterror();  // drop the pending message; the caller's names the extension
        return 0;
    }
    return out->supports("alpha") ? 4 : 3;
}

int vrmlray_oiio_write(const char* path, int width, int height, int channels, int format,
                       const void* samples, int srgb, char* error, size_t error_size) {
    try {
        auto out = OIIO::ImageOutput::create(path);
        if (!out) {
            set_error(error, error_size, oiio_error(""));
            return 0;
        }
        const std::string ext = lower_extension(path);
        OIIO::ImageSpec spec(width, height, channels, type_of(format));
        if (channels == 2 || channels == 4) {
            spec.alpha_channel = channels - 1;
            // Float samples come premultiplied (EXR's convention); integer ones straight.
            if (format != VR_OIIO_FLOAT) spec.attribute("oiio:UnassociatedAlpha", 1);
        }
        if (format != VR_OIIO_FLOAT && srgb) spec.attribute("oiio:ColorSpace", "sRGB");
        if (ext == "exr") spec.attribute("compression", "zip");
        if (ext == "jpg" || ext == "jpeg") spec.attribute("Compression", "jpeg:95");
        if (ext == "ppm" || ext == "pnm") spec.attribute("pnm:binary", 1);
        spec.attribute("Software", "vrmlray");
        // OpenImageIO stamps the current time otherwise (EXR capDate, TIFF DateTime): the same
        // render must write the same bytes (docs/manual.md, render).
        spec.attribute("DateTime", "");
        if (!out->open(path, spec)) {
            set_error(error, error_size, oiio_error(out->geterror()));
            return 0;
        }
        const bool ok = out->write_image(type_of(format), samples);
        const bool closed = out->close();
        if (!ok || !closed) {
            set_error(error, error_size, oiio_error(out->geterror()));
            return 0;
        }
        return 1;
    } catch (const std::exception& e) {
        set_error(error, error_size, e.what());
        return 0;
    }
}

}  // extern "C"
