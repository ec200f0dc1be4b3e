#include "image/oiio_module.h"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <mutex>
#include <system_error>

#include "image/module_path.h"

namespace vr {
namespace {

constexpr const char* kModuleName = "vrmlray_oiio.so";
constexpr size_t kErrorSize = 1024;

std::string dl_error() {
    const char* e = dlerror();
    return e ? e : "unknown dlopen error";
}

template <typename Fn>
bool symbol(void* handle, const char* name, Fn& fn, std::string& why) {
    dlerror();
    fn = reinterpret_cast<Fn>(dlsym(handle, name));
    if (!fn) why = dl_error();
    return fn != nullptr;
}

// Opens one candidate and binds its functions; `why` is the reason it failed.
bool try_load(const std::string& path, OiioModule& module, std::string& why) {
    // RTLD_LOCAL: OpenImageIO's symbols stay out of the global namespace.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        why = dl_error();
        return false;
    }
    // A handle whose symbols do not fit stays open: its static initialisers have run, and
    // unloading OpenImageIO's dependency tree again is not worth the risk.
    OiioModule m;
    m.path = path;
    m.handle = handle;
    VrOiioAbiVersionFn version = nullptr;
    if (!symbol(handle, "vrmlray_oiio_abi_version", version, why)) return false;
    if (version() != VRMLRAY_OIIO_ABI_VERSION) {
        why = "it has interface version " + std::to_string(version()) + ", vrmlray needs " +
              std::to_string(VRMLRAY_OIIO_ABI_VERSION);
        return false;
    }
    if (!symbol(handle, "vrmlray_oiio_open", m.open, why) ||
        !symbol(handle, "vrmlray_oiio_read", m.read, why) ||
        !symbol(handle, "vrmlray_oiio_close", m.close, why) ||
        !symbol(handle, "vrmlray_oiio_output_channels", m.output_channels, why) ||
        !symbol(handle, "vrmlray_oiio_write", m.write, why))
        return false;
    module = m;
    return true;
}

}  // namespace

#ifndef VRMLRAY_OIIO_MODULE_PATH
#define VRMLRAY_OIIO_MODULE_PATH ""
#endif

std::vector<std::string> oiio_module_candidates() {
    return module_candidates(kModuleName, VRMLRAY_OIIO_MODULE_PATH);
}

bool load_oiio_module(const std::vector<std::string>& candidates, OiioModule& module,
                      std::string& error) {
    struct Failure {
        std::string path, why;
        bool exists = false;
    };
    std::vector<Failure> failures;
    for (const std::string& path : candidates) {
        Failure f{path, "", false};
        if (try_load(path, module, f.why)) return true;
        std::error_code ec;
        f.exists = std::filesystem::exists(path, ec);
        failures.push_back(f);
    }
    if (failures.empty()) {
        error = "the OpenImageIO module could not be loaded: nowhere to look for it";
        return false;
    }
    // The headline is the first candidate that exists (why it failed is the news), else the first.
    size_t head = 0;
    for (size_t i = 0; i < failures.size(); ++i)
        if (failures[i].exists) {
            head = i;
            break;
        }
    error = "the OpenImageIO module " + failures[head].path +
            " could not be loaded: " + failures[head].why;
    std::string others;
    for (size_t i = 0; i < failures.size(); ++i)
        if (i != head)
            others += (others.empty() ? "" : "; ") + failures[i].path + ": " + failures[i].why;
    if (!others.empty()) error += " (also tried " + others + ")";
    return false;
}

const OiioModule* oiio_module(std::string& error) {
    static std::once_flag once;
    static OiioModule module;
    static bool loaded = false;
    static std::string load_error;
    std::call_once(once,
                   [] { loaded = load_oiio_module(oiio_module_candidates(), module, load_error); });
    if (!loaded) {
        error = load_error;
        return nullptr;
    }
    return &module;
}

bool oiio_read_pixels(const std::string& path, int max_channels, size_t max_pixels,
                      OiioPixels& pixels, std::string& error) {
    const OiioModule* m = oiio_module(error);
    if (!m) return false;
    char message[kErrorSize] = "";
    VrOiioSpec spec{};
    VrOiioInput* in = m->open(path.c_str(), 1, &spec, message, sizeof message);
    if (!in) {
        error = message[0] ? message : "cannot open the image";
        return false;
    }
    struct Closer {
        const OiioModule* m;
        VrOiioInput* in;
        ~Closer() { m->close(in); }
    } closer{m, in};
    if (spec.width <= 0 || spec.height <= 0 || spec.channels <= 0 || spec.deep) {
        error = "not a flat image with pixels";
        return false;
    }
    const uint64_t npix = uint64_t(spec.width) * uint64_t(spec.height);
    if (npix > max_pixels) {
        error = "the image is too large (" + std::to_string(spec.width) + " x " +
                std::to_string(spec.height) + " = " + std::to_string(npix) +
                " pixels; the limit is " + std::to_string(max_pixels) + ")";
        return false;
    }
    const int nch = std::min(spec.channels, max_channels);
    std::vector<float> samples(size_t(npix) * size_t(nch));
    bool ok = false;
    if (spec.format == VR_OIIO_UINT8) {
        std::vector<uint8_t> codes(samples.size());
        ok = m->read(in, nch, VR_OIIO_UINT8, codes.data(), message, sizeof message);
        for (size_t i = 0; ok && i < codes.size(); ++i) samples[i] = float(codes[i]) / 255.0f;
    } else if (spec.format == VR_OIIO_UINT16) {
        std::vector<uint16_t> codes(samples.size());
        ok = m->read(in, nch, VR_OIIO_UINT16, codes.data(), message, sizeof message);
        for (size_t i = 0; ok && i < codes.size(); ++i) samples[i] = float(codes[i]) / 65535.0f;
    } else {
        ok = m->read(in, nch, VR_OIIO_FLOAT, samples.data(), message, sizeof message);
    }
    if (!ok) {
        error = message[0] ? message : "cannot read the image";
        return false;
    }
    pixels.width = spec.width;
    pixels.height = spec.height;
    pixels.channels = nch;
    pixels.alpha_channel = spec.alpha_channel;
    pixels.samples = std::move(samples);
    return true;
}

bool oiio_write_pixels(const std::string& path, int width, int height, int channels, int format,
                       const void* samples, bool srgb, std::string& error) {
    const OiioModule* m = oiio_module(error);
    if (!m) return false;
    char message[kErrorSize] = "";
    if (!m->write(path.c_str(), width, height, channels, format, samples, srgb ? 1 : 0, message,
                  sizeof message)) {
        error = message[0] ? message : "cannot write the image";
        return false;
    }
    return true;
}

int oiio_output_channels(const std::string& path, std::string& error) {
    const OiioModule* m = oiio_module(error);
    if (!m) return -1;
    return m->output_channels(path.c_str());
}

}  // namespace vr
