// A path in the temporary folder that no other test process uses: CTest runs the tests in parallel
// processes, so two tests (or two runs) must never share a fixed file or folder name.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <string>

namespace vr::test {

inline std::filesystem::path temp_path(const std::string& name) {
    return std::filesystem::temp_directory_path() /
           (name + "_" + std::to_string(static_cast<long>(::getpid())));
}

}  // namespace vr::test
