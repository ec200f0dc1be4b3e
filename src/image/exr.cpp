#include "image/exr.h"

#include <dlfcn.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "image/exr_abi.h"
#include "image/module_path.h"

namespace vr {
namespace {

constexpr const char* kModuleName = "vrmlray_exr.so";

struct ExrModule {
    VrExrHeaderFn header = nullptr;
    VrExrReadFn read = nullptr;
    VrExrWriteFn write = nullptr;
};

template <typename Fn>
bool bind(void* handle, const char* name, Fn& fn) {
    fn = reinterpret_cast<Fn>(dlsym(handle, name));
    return fn != nullptr;
}

#ifndef VRMLRAY_EXR_MODULE_PATH
#define VRMLRAY_EXR_MODULE_PATH ""
#endif

bool load(ExrModule& m, std::string& error) {
    const std::vector<std::string> candidates =
        module_candidates(kModuleName, VRMLRAY_EXR_MODULE_PATH);
    // The headline is the first candidate that exists (why it failed is the news), else the first.
    std::string head, why = "nowhere to look for it";
    bool head_exists = false;
    for (const std::string& path : candidates) {
        void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        std::string reason;
        if (handle) {
            VrExrAbiVersionFn version = nullptr;
            if (bind(handle, "vrmlray_exr_abi_version", version) &&
                version() == VRMLRAY_EXR_ABI_VERSION &&
                bind(handle, "vrmlray_exr_header", m.header) &&
                bind(handle, "vrmlray_exr_read", m.read) &&
                bind(handle, "vrmlray_exr_write", m.write))
                return true;
            reason = "it lacks vrmlray's OpenEXR interface version " +
                     std::to_string(VRMLRAY_EXR_ABI_VERSION);
        } else {
            const char* e = dlerror();
            reason = e ? e : "unknown dlopen error";
        }
        std::error_code ec;
        const bool exists = std::filesystem::exists(path, ec);
        if (head.empty() || (exists && !head_exists))
            head = path, why = reason, head_exists = exists;
    }
    error = "the OpenEXR module " + (head.empty() ? std::string(kModuleName) : head) +
            " could not be loaded: " + why;
    return false;
}

const ExrModule* exr_module(std::string& error) {
    static std::once_flag once;
    static ExrModule module;
    static bool loaded = false;
    static std::string load_error;
    std::call_once(once, [] { loaded = load(module, load_error); });
    if (!loaded) error = load_error;
    return loaded ? &module : nullptr;
}

bool is_exr(const std::string& path) {
    unsigned char magic[4] = {};
    FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return false;
    const bool whole = std::fread(magic, 1, 4, f) == 4;
    std::fclose(f);
    return whole && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01;
}

}  // namespace

ExrStatus read_exr(const std::string& path, size_t max_pixels, ExrPixels& pixels,
                   std::string& error) {
    if (!is_exr(path)) return ExrStatus::kNotExr;
    const ExrModule* m = exr_module(error);
    if (!m) return ExrStatus::kError;
    char message[1024] = "";
    VrExrSpec spec{};
    if (!m->header(path.c_str(), &spec, message, sizeof message)) {
        error = message;
        return ExrStatus::kError;
    }
    if (spec.channels == 0) return ExrStatus::kOtherChannels;
    const uint64_t npix = uint64_t(spec.width) * uint64_t(spec.height);
    if (spec.width <= 0 || spec.height <= 0 || npix > max_pixels) {
        error = "the image is too large (" + std::to_string(spec.width) + " x " +
                std::to_string(spec.height) + " = " + std::to_string(npix) +
                " pixels; the limit is " + std::to_string(max_pixels) + ")";
        return ExrStatus::kError;
    }
    std::vector<float> samples(size_t(npix) * size_t(spec.channels));
    if (!m->read(path.c_str(), &spec, samples.data(), message, sizeof message)) {
        error = message;
        return ExrStatus::kError;
    }
    pixels.width = spec.width;
    pixels.height = spec.height;
    pixels.channels = spec.channels;
    pixels.samples = std::move(samples);
    return ExrStatus::kOk;
}

bool exr_available(std::string& error) { return exr_module(error) != nullptr; }

bool write_exr(const std::string& path, int width, int height, int channels, const float* samples,
               std::string& error) {
    const ExrModule* m = exr_module(error);
    if (!m) return false;
    char message[1024] = "";
    if (m->write(path.c_str(), width, height, channels, samples, message, sizeof message))
        return true;
    error = message;
    std::remove(path.c_str());
    return false;
}

}  // namespace vr
