#include "app/progress.h"

#include <unistd.h>

#include <cstdio>

namespace vr {

ProgressBar::ProgressBar(bool enabled)
    : enabled_(enabled && isatty(STDERR_FILENO)), start_(std::chrono::steady_clock::now()) {}

void ProgressBar::update(double fraction, uint64_t rays) {
    if (!enabled_) return;
    double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (elapsed < 0.5 && fraction < 1.0) return;  // short renders show no bar
    double remaining = fraction > 0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    double rate = elapsed > 0 ? static_cast<double>(rays) / elapsed : 0.0;
    const int width = 30;
    int filled = static_cast<int>(fraction * width + 0.5);
    char bar[width + 1];
    for (int i = 0; i < width; ++i) bar[i] = i < filled ? '#' : '.';
    bar[width] = '\0';
    std::fprintf(stderr, "\r[%s] %5.1f%%  %6.1fs elapsed  %6.1fs left  %7.2f Mrays/s", bar,
                 fraction * 100.0, elapsed, remaining, rate * 1e-6);
    std::fflush(stderr);
    drawn_ = true;
}

void ProgressBar::finish() {
    if (drawn_) std::fprintf(stderr, "\n");
    drawn_ = false;
}

}  // namespace vr
