// The OpenEXR module: see image/exr_abi.h. Every OpenEXR exception stops here, as an error message.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <cstdio>
#include <exception>

#include "image/exr_abi.h"

namespace {

void set_error(char* error, size_t size, const char* message) {
    if (error && size) std::snprintf(error, size, "%s", message);
}

constexpr const char* kRgba[] = {"R", "G", "B", "A"};
constexpr const char* kYa[] = {"Y", "A"};

const char* const* channel_names(int channels) { return channels <= 2 ? kYa : kRgba; }

}  // namespace

extern "C" {

__attribute__((visibility("default"))) int vrmlray_exr_abi_version(void) {
    return VRMLRAY_EXR_ABI_VERSION;
}

__attribute__((visibility("default"))) int vrmlray_exr_header(const char* path, VrExrSpec* spec,
                                                              char* error, size_t error_size) {
    try {
        Imf::InputFile file(path);
        const Imath::Box2i window = file.header().dataWindow();
        const Imf::ChannelList& list = file.header().channels();
        spec->width = window.max.x - window.min.x + 1;
        spec->height = window.max.y - window.min.y + 1;
        const bool alpha = list.findChannel("A") != nullptr;
        if (list.findChannel("R") && list.findChannel("G") && list.findChannel("B"))
            spec->channels = alpha ? 4 : 3;
        else if (list.findChannel("Y"))
            spec->channels = alpha ? 2 : 1;
        else
            spec->channels = 0;
        return 1;
    } catch (const std::exception& e) {
        set_error(error, error_size, e.what());
        return 0;
    }
}

__attribute__((visibility("default"))) int vrmlray_exr_read(const char* path, const VrExrSpec* spec,
                                                            float* samples, char* error,
                                                            size_t error_size) {
    try {
        Imf::InputFile file(path);
        const Imath::Box2i window = file.header().dataWindow();
        const size_t nch = size_t(spec->channels);
        const size_t xstride = sizeof(float) * nch, ystride = xstride * size_t(spec->width);
        // The frame buffer is addressed by absolute pixel coordinates: shift the base so that the
        // data window's corner lands on samples[0].
        char* base = reinterpret_cast<char*>(samples) -
                     ptrdiff_t(window.min.x) * ptrdiff_t(xstride) -
                     ptrdiff_t(window.min.y) * ptrdiff_t(ystride);
        Imf::FrameBuffer frame;
        const char* const* names = channel_names(spec->channels);
        for (size_t c = 0; c < nch; ++c)
            frame.insert(names[c],
                         Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xstride, ystride, 1, 1,
                                    c == 3 || (nch == 2 && c == 1) ? 1.0 : 0.0));
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        return 1;
    } catch (const std::exception& e) {
        set_error(error, error_size, e.what());
        return 0;
    }
}

__attribute__((visibility("default"))) int vrmlray_exr_write(const char* path, int width,
                                                             int height, int channels,
                                                             const float* samples, char* error,
                                                             size_t error_size) {
    try {
        Imf::Header header(width, height);
        header.compression() = Imf::ZIP_COMPRESSION;
        header.insert("Software", Imf::StringAttribute("vrmlray"));
        Imf::FrameBuffer frame;
        const size_t xstride = sizeof(float) * size_t(channels);
        const size_t ystride = xstride * size_t(width);
        for (int c = 0; c < channels; ++c) {
            header.channels().insert(kRgba[c], Imf::Channel(Imf::FLOAT));
            frame.insert(kRgba[c],
                         Imf::Slice(Imf::FLOAT,
                                    const_cast<char*>(reinterpret_cast<const char*>(samples + c)),
                                    xstride, ystride));
        }
        Imf::OutputFile file(path, header);
        file.setFrameBuffer(frame);
        file.writePixels(height);
        return 1;
    } catch (const std::exception& e) {
        set_error(error, error_size, e.what());
        return 0;
    }
}

}  // extern "C"
