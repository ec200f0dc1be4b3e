// Where vrmlray's dlopen-ed modules (vrmlray_oiio.so, vrmlray_exr.so) are looked for, in order:
// next to the running executable (the build folder), PREFIX/lib/vrmlray/ beside PREFIX/bin/vrmlray
// (cmake --install, the .deb), then the folder CMake built it in (a compiled-in path, for test
// binaries in other folders).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace vr {

inline std::vector<std::string> module_candidates(const char* file_name, const char* built_path) {
    std::vector<std::string> out;
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec && !exe.empty()) {
        out.push_back((exe.parent_path() / file_name).string());
        out.push_back((exe.parent_path().parent_path() / "lib" / "vrmlray" / file_name).string());
    }
    if (built_path && *built_path) {
        bool seen = false;
        for (const std::string& p : out) seen = seen || p == built_path;
        if (!seen) out.push_back(built_path);
    }
    if (out.empty()) out.push_back(file_name);  // the dynamic loader's own search
    return out;
}

}  // namespace vr
