#include "image/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace vr {

FILE* open_output(const std::string& path, std::string& error) {
    // O_WRONLY without O_TRUNC: the old contents stay until overwritten (see the header).
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) {
        error = std::strerror(errno);
        return nullptr;
    }
    FILE* f = ::fdopen(fd, "wb");
    if (f == nullptr) {
        error = std::strerror(errno);
        ::close(fd);
    }
    return f;
}

bool close_output(FILE* f, std::string& error) {
    bool ok = std::fflush(f) == 0 && !std::ferror(f);
    if (ok) {
        // Pipes and devices (/dev/stdout, /dev/null) have no length to cut.
        struct stat st;
        if (::fstat(::fileno(f), &st) == 0 && S_ISREG(st.st_mode)) {
            const long end = std::ftell(f);
            ok = end >= 0 && ::ftruncate(::fileno(f), off_t(end)) == 0;
        }
    }
    const int saved = errno;
    const bool closed = std::fclose(f) == 0;
    if (!ok || !closed) error = std::string("write error: ") + std::strerror(ok ? errno : saved);
    return ok && closed;
}

}  // namespace vr
