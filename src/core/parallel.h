// A minimal fork-join loop over index ranges on std::thread (no pool: the callers are coarse,
// one call per build step).
#pragma once
#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace vr {

// Calls body(begin, end, chunk) for `chunks` contiguous ranges of [0, n), chunk 0 on the calling
// thread. The split depends only on n and chunks, never on timing.
template <class Body>
void parallel_ranges(size_t n, int chunks, Body&& body) {
    chunks = int(std::max<size_t>(1, std::min<size_t>(size_t(std::max(chunks, 1)), n)));
    if (chunks == 1) {
        body(size_t(0), n, 0);
        return;
    }
    std::vector<std::thread> workers;
    workers.reserve(size_t(chunks - 1));
    auto bounds = [&](int c) { return n * size_t(c) / size_t(chunks); };
    for (int c = 1; c < chunks; ++c)
        workers.emplace_back([&, c] { body(bounds(c), bounds(c + 1), c); });
    body(bounds(0), bounds(1), 0);
    for (std::thread& t : workers) t.join();
}

// How many chunks to use for n items of cheap work: one thread per ~64k items, at most `threads`.
inline int chunks_for(size_t n, int threads) {
    return int(std::max<size_t>(1, std::min<size_t>(size_t(std::max(threads, 1)), n / 65536)));
}

}  // namespace vr
