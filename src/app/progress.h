// A progress bar on stderr, shown only when stderr is a terminal.
#pragma once
#include <chrono>
#include <cstdint>

namespace vr {

class ProgressBar {
  public:
    explicit ProgressBar(bool enabled);
    void update(double fraction, uint64_t rays);
    void finish();

  private:
    bool enabled_;
    bool drawn_ = false;
    std::chrono::steady_clock::time_point start_;
};

}  // namespace vr
